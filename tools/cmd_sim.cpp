// `epichead sim SCENARIO --out SEQ [--frames N] [--seed S] [--variety V] [--jerk K]`: runs a simulator scenario
// (a built-in name or a .scn file) and writes a sequence directory with ground truth and IMU.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "command.h"
#include "progress.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sequence_writer.h"

namespace epichead::tools {
namespace {

std::string builtin_list() {
  std::string names;
  for (const auto& n : sim::builtin_scenario_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

const CommandRegistration registration{
    "sim", "Simulate a scenario into a sequence directory (frames, gt.csv, init.csv, imu.csv)",
    [](CLI::App& app) {
      auto scenario = std::make_shared<std::string>();
      auto out = std::make_shared<std::string>();
      auto frames = std::make_shared<int>(0);
      auto seed = std::make_shared<std::uint64_t>(0);
      auto jerk = std::make_shared<double>(1.0);
      auto variety = std::make_shared<double>(0.0);
      app.add_option("scenario", *scenario, "Built-in scenario (" + builtin_list() + ") or a .scn file")->required();
      app.add_option("--out", *out, "Sequence directory to write (created; an earlier simulator output is replaced)")
          ->required();
      CLI::Option* frames_opt = app.add_option("--frames", *frames, "Number of frames (overrides the scenario)")->check(CLI::Range(1, 1000000));
      CLI::Option* seed_opt = app.add_option("--seed", *seed, "Random seed (overrides the scenario); output is identical for a seed. "
                                                              "Without --variety it also draws a new scene (variety 1)");
      CLI::Option* variety_opt =
          app.add_option("--variety", *variety,
                         "How far the seed moves the scene from the built-in one: 0 = as built, 1 = full variety "
                         "(background, light, object look and placement, camera path, occluders). "
                         "Default: the scenario's value, or 1 when --seed is given")
              ->check(CLI::Range(0.0, 1.0));
      CLI::Option* jerk_opt = app.add_option("--jerk", *jerk, "Scale of the body's jerks: the walking robot's angular-rate bursts and bob, or the hand-held camera's shakes")
          ->check(CLI::Range(0.0, 20.0));
      app.footer("Built-in scenarios: " + builtin_list() + ". Format of .scn files: sim/scenarios/README.md.");
      return [=]() -> int {
        auto s = sim::find_scenario(*scenario);
        if (!s) return fail("sim", s.error());
        if (frames_opt->count() > 0) s->frames = *frames;
        if (seed_opt->count() > 0) s->seed = *seed;
        // Asking for another seed means asking for another scene, unless the variety is given.
        if (variety_opt->count() > 0) s->variety = *variety;
        else if (seed_opt->count() > 0) s->variety = 1.0;
        if (jerk_opt->count() > 0) {
          if (s->motion == sim::MotionKind::walking) s->walking.jerk = *jerk;
          else if (s->motion == sim::MotionKind::handheld) s->handheld.jerk = *jerk;
          else return fail("sim", "--jerk applies to walking and hand-held motion; scenario '" + s->name + "' is wheeled");
        }
        // Frames rendered and written, on stderr when it is a terminal (progress.h).
        Progress progress("sim", "frames", s->frames);
        auto summary = sim::write_sequence(*s, *out, [&progress](int i, int n) {
          progress.set_total(n);
          progress.update(i + 1);
        });
        if (!summary) return fail("sim", summary.error());
        progress.finish();
        std::printf("epichead sim: wrote %s (scenario %s, seed %llu, variety %g)\n", out->c_str(), s->name.c_str(),
                    static_cast<unsigned long long>(s->seed), s->variety);
        std::printf("%d frames over %.2f s, peak body angular rate %.1f deg/s, %d IMU samples (%d dropped, %d saturated)\n",
                    summary->frames, summary->duration_s, summary->peak_body_rate_degps, summary->imu_samples,
                    summary->imu_dropped, summary->imu_saturated);
        return 0;
      };
    }};

}  // namespace
}  // namespace epichead::tools
