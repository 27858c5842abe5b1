// `epichead sim-run` end to end (issue 9, items 4-5): the closed loop stabilises the camera
// against the fixed head, writes its summary, timeline, plots and a bus log that `epichead
// replay` reads, and rejects bad input with one line.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/readme_columns.h"
#include "common/run_tool.h"
#include "common/temp_dir.h"

using epichead::testing::run_epichead;
using epichead::testing::lines_of;
using epichead::testing::slurp;
using epichead::testing::TempDir;

namespace {

// summary.json of `sim-run ARGS --every 0 --out DIR/out`, which must succeed.
nlohmann::json sim_run_summary(const TempDir& dir, const std::string& args) {
  const auto r = run_epichead(dir, "sim-run " + args + " --every 0 --out '" + dir.str() + "/out'");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(slurp(dir / "out/summary.json"));
}

}  // namespace

TEST_CASE("sim-run: the stabilised camera turns several times slower than with the head fixed, the log replays",
          "[tools][sim-run]") {
  TempDir dir("sim_run");
  // 2 s in stabilise mode at a small camera (vision is not used in that mode), two bursts.
  const auto r = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() +
                                       "/out' --seconds 2 --mode stabilise --downscale 8 --every 0 --settle-s 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(slurp(dir / "out/summary.json"));
  const auto& rate = j["camera_rate_rms_degps"];
  INFO(rate.dump());
  CHECK(rate["fixed_head"].get<double>() > 5.0);
  CHECK(rate["reduction"].get<double>() > 5.0);
  CHECK(j["loop"]["commands_sent"].get<int>() > 1900);
  CHECK(j["loop"]["result_to_command_ms_max"].get<double>() <= 2.0);
  // The truth timeline: a header and one row per millisecond.
  std::istringstream timeline(slurp(dir / "out/timeline.csv"));
  std::string line;
  int rows = -1;
  while (std::getline(timeline, line)) ++rows;
  CHECK(rows >= 1999);
  CHECK(std::filesystem::file_size(dir / "out/sim_run.png") > 10000);

  const auto replay = run_epichead(dir, "replay '" + dir.str() + "/out/bus.log' --json");
  INFO(replay.err);
  REQUIRE(replay.exit_code == 0);
  const auto rj = nlohmann::json::parse(replay.out);
  CHECK(rj["malformed_lines"].get<int>() == 0);
  std::map<std::string, int> counts;
  for (const auto& id : rj["ids"]) counts[id["message"].get<std::string>()] += id["count"].get<int>();
  CHECK(counts["HeadCommand"] > 1900);  // one per 1 ms tick once the head state is known
  CHECK(counts["ImuGyro"] > 1900);      // the 1 kHz IMU
  CHECK(counts["HeadState"] > 350);     // 200 Hz
}

namespace {

// A candump line's stamp in microseconds: "(1704067200.000217) can0 ..." -> 1704067200000217.
std::int64_t stamp_us(const std::string& line) {
  const auto dot = line.find('.');
  return std::stoll(line.substr(1, dot - 1)) * 1'000'000 + std::stoll(line.substr(dot + 1, 6));
}

}  // namespace

TEST_CASE("sim-run: bus.log starts at the fixed epoch 2024-01-01 and merges by time with a candump taken beside it",
          "[tools][sim-run]") {
  TempDir dir("sim_run_epoch");
  const auto r = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() +
                                       "/out' --seconds 1 --mode stabilise --downscale 8 --every 0 --settle-s 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const std::vector<std::string> ours = lines_of(slurp(dir / "out/bus.log"));
  REQUIRE(ours.size() > 3000);
  CHECK(ours.front().rfind("(1704067200.000000) can0 ", 0) == 0);  // simulated time 0
  // On the wall clock, in order but for the time-sync request a tick sends before it reads the
  // frames that came in during the tick before (stamped up to one tick earlier).
  std::int64_t latest = 0;
  for (const auto& line : ours) {
    INFO(line);
    const std::int64_t t = stamp_us(line);
    REQUIRE(t > 1'000'000'000'000'000);
    REQUIRE(t > latest - 1000);
    latest = std::max(latest, t);
  }
  CHECK(latest >= 1'704'067'200'999'000);  // the last tick, 1 s on (or one before it)
  CHECK(latest <= 1'704'067'201'000'000);
  // The diagnostics stream keeps simulated time and records the mapping first.
  CHECK(lines_of(slurp(dir / "out/diagnostics.jsonl")).front() ==
        "{\"t_s\":0.000000,\"clock_map\":{\"monotonic_s\":0.000000,\"unix_s\":1704067200.000000}}");

  // Another device's candump log over the same second (100 Hz from 0.25 ms), merged by time as
  // one would merge two candump logs: replay sees one second of bus with both.
  std::vector<std::string> merged = ours;
  for (int i = 0; i < 100; ++i) {
    char line[64];
    std::snprintf(line, sizeof line, "(1704067200.%06d) can1 3A0#0102030405060708", 250 + i * 10'000);
    merged.push_back(line);
  }
  std::stable_sort(merged.begin(), merged.end(),
                   [](const std::string& a, const std::string& b) { return stamp_us(a) < stamp_us(b); });
  std::string text;
  for (const auto& line : merged) text += line + "\n";
  const std::string merged_path = dir.write("merged.log", text);
  const auto replay = run_epichead(dir, "replay '" + merged_path + "' --json");
  INFO(replay.err);
  REQUIRE(replay.exit_code == 0);
  const auto rj = nlohmann::json::parse(replay.out);
  CHECK(rj["malformed_lines"].get<int>() == 0);
  CHECK(rj["duration_s"].get<double>() == Approx(1.0).margin(0.0011));  // seconds, not 1.7e9
  std::map<std::string, nlohmann::json> by_id;
  for (const auto& id : rj["ids"]) by_id[id["id"].get<std::string>()] = id;
  REQUIRE(by_id.count("0x3A0") == 1);
  CHECK(by_id["0x3A0"]["count"].get<int>() == 100);
  CHECK(by_id["0x3A0"]["rate_hz"].get<double>() == Approx(100).margin(1));
  CHECK(by_id["0x100"]["rate_hz"].get<double>() == Approx(1000).margin(5));  // HeadCommand, one per tick
}

TEST_CASE("sim-run --log-epoch sets where simulated time 0 lands in bus.log", "[tools][sim-run]") {
  TempDir dir("sim_run_log_epoch");
  const auto r = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() +
                                       "/out' --seconds 0.1 --mode stabilise --downscale 8 --every 0 --settle-s 0 "
                                       "--log-epoch 1436509052.25");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(slurp(dir / "out/bus.log").rfind("(1436509052.250000) can0 ", 0) == 0);
  const auto bad = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() + "/o' --log-epoch yesterday");
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("--log-epoch must be Unix seconds") != std::string::npos);
}

TEST_CASE("sim-run rejects bad input with one line naming the reason", "[tools][sim-run]") {
  TempDir dir("sim_run_bad");
  const auto mode = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() + "/o' --mode dance");
  CHECK(mode.exit_code != 0);
  CHECK(mode.err.find("--mode must be fixate, stabilise or hold") != std::string::npos);
  const auto scn = run_epichead(dir, "sim-run no_such_scene --out '" + dir.str() + "/o'");
  CHECK(scn.exit_code != 0);
  CHECK(scn.err.find("no_such_scene") != std::string::npos);
  // The object's up is read before anything runs (it was once taken and never used).
  const auto up = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() + "/o' --object-up 0,0,0");
  CHECK(up.exit_code != 0);
  CHECK(up.err.find("--object-up must be x,y,z, a non-zero direction") != std::string::npos);
}

TEST_CASE("sim-run --soak: the closed run alone, with memory and the predictor's attitude error reported",
          "[tools][sim-run][soak]") {
  TempDir dir("sim_run_soak");
  const std::string scn = dir.write("soak.scn", slurp(std::string(EPICHEAD_SOURCE_DIR) + "/sim/scenarios/mockup_walk.scn") +
                                                    "fault imu_dropout 2.0 0.3\n");
  const auto r = run_epichead(dir, "sim-run '" + scn + "' --out '" + dir.str() +
                                       "/out' --seconds 4 --soak --soak-warmup-s 1 --downscale 2 --every 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("memory:") != std::string::npos);
  const auto j = nlohmann::json::parse(slurp(dir / "out/summary.json"));
  const auto& soak = j["soak"];
  INFO(soak.dump());
  CHECK(soak["rss_kib_after_warmup"].get<double>() > 1000);
  CHECK(soak["rss_kib_end"].get<double>() > 1000);
  CHECK(soak["rss_kib_max"].get<double>() >= soak["rss_kib_end"].get<double>());
  CHECK(soak["frames"].get<int>() >= 100);
  // Tracking from a 1 deg initial error: the prediction stays within a few degrees.
  CHECK(j["loop"]["lost"].get<int>() == 0);
  CHECK(soak["predicted_attitude_error_deg_median_early"].get<double>() >= 0);
  CHECK(soak["predicted_attitude_error_deg_median_late"].get<double>() < 3.0);
  // The dropout was raised and cleared in the diagnostics stream; no bus log or timeline.
  const std::string diag = slurp(dir / "out/diagnostics.jsonl");
  CHECK(diag.find("\"fault\":\"imu_stale\"") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "out/bus.log"));
  CHECK_FALSE(std::filesystem::exists(dir / "out/timeline.csv"));
}

// docs/head.md section 5: a gear play four times the nominal one that the controller is not told
// of cut the reduction to 3.4x and set the camera hunting across the band; the online estimate
// (head/backlash_estimate.h) finds it and the compensation takes it.
TEST_CASE("sim-run: a 2 mrad backlash the controller is not told of is estimated online and the rate still cut 5x",
          "[tools][sim-run][backlash]") {
  TempDir dir("sim_run_untold_backlash");
  const std::string scn = dir.write("backlash.scn", slurp(std::string(EPICHEAD_SOURCE_DIR) + "/sim/scenarios/mockup_walk.scn") +
                                                        "head_backlash_rad 0.002\n");
  const auto r = run_epichead(dir, "sim-run '" + scn + "' --out '" + dir.str() +
                                       "/out' --seconds 10 --mode stabilise --downscale 8 --every 0 --told-backlash-rad 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(slurp(dir / "out/summary.json"));
  const auto& c = j["loop"]["controller"];
  INFO(j["camera_rate_rms_degps"].dump() << " " << c.dump());
  CHECK(c["backlash_samples"].get<int>() >= 10);
  for (const char* joint : {"pan", "tilt"}) {
    const double band = c["backlash_band_rad"][joint].get<double>();
    CHECK(band > 0.6 * 0.002);  // 0.85 of the estimate
    CHECK(band <= 0.002);       // never wider than the play: too wide costs more than too narrow
  }
  CHECK(j["camera_rate_rms_degps"]["reduction"].get<double>() > 5.0);
}

// The soak's drift (docs/head.md section 6), in ten seconds: a bus-off 0.1 s into a walking
// step's burst silences the IMU (it is on the same bus) while the head, without commands, lets
// the camera swing with the body. From the predictor's pose alone the tracker settled on a pose
// 18-30 deg off, almost all of it a tilt; the accelerometer's down against the object's learnt
// down (fusion/learnt_gravity.h) refused it (before that check, 100 frames after the bus-off were
// tracked 15-31 deg off), and now the vision-only second opinion keeps the tracker on the object.
namespace {

struct BusOffRun {
  nlohmann::json summary;
  int tracked_off_10deg_after_fault = 0;  // frames tracked with the tracker's pose > 10 deg off
};

BusOffRun run_bus_off(TempDir& dir) {
  const std::string scn = dir.write("bus_off.scn", slurp(std::string(EPICHEAD_SOURCE_DIR) + "/sim/scenarios/mockup_walk.scn") +
                                                       "fault bus_off 6.0 0.3\n");
  const auto r = run_epichead(dir, "sim-run '" + scn + "' --out '" + dir.str() +
                                       "/out' --seconds 10 --soak --soak-warmup-s 1 --downscale 2 --every 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  BusOffRun run;
  run.summary = nlohmann::json::parse(slurp(dir / "out/summary.json"));
  const auto rows = lines_of(slurp(dir / "out/attitude_error.csv"));
  REQUIRE(rows.size() > 200);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    double t = 0, predicted = 0, tracked = 0;
    if (std::sscanf(rows[i].c_str(), "%lf,%lf,%lf", &t, &predicted, &tracked) == 3 && t > 6.0 && tracked > 10.0)
      ++run.tracked_off_10deg_after_fault;
  }
  return run;
}

}  // namespace

TEST_CASE("sim-run --soak: after a bus-off inside a step's burst no tilted lock is tracked", "[tools][sim-run][soak]") {
  TempDir dir("sim_run_bus_off_refused");
  const BusOffRun run = run_bus_off(dir);
  INFO(run.summary.dump());
  // Before the vision-only second opinion (head/src/vision_stage.h, 2026-12-07) the tracker
  // took tilted locks from the predictor's pose right after the gap: the predictor did not
  // restart from them (Unchecked), the accelerometer's check refused 15 (against_gravity), and 7
  // frames (6.13-6.43 s) were tracked 16-19 deg off. Now the one frame the predictor's pose loses
  // is measured from the vision poses' own extrapolation, and no lock forms: 294 of 294 frames
  // tracked, none off by more than 10 deg. (The refusal itself: tests/fusion/test_learnt_gravity.cpp.)
  CHECK(run.summary["loop"]["fallback_frames"].get<int>() >= 1);
  CHECK(run.summary["loop"]["lost"].get<int>() <= 5);
  CHECK(run.tracked_off_10deg_after_fault == 0);
}

// The onboard loop's own wiring of the tilt check (the check itself: tests/fusion/
// test_learnt_gravity.cpp), which the bus-off run above no longer reaches: told an up the poses
// contradict (the mockup stands with its model's z up, told x), the loop refuses every tracked
// pose as against gravity and counts the frame lost; told the right up, it refuses none.
TEST_CASE("sim-run: the onboard loop takes a tracked pose whose tilt contradicts the told up as lost, and counts it", "[tools][sim-run]") {
  TempDir dir("sim_run_against_gravity");
  const auto wrong = sim_run_summary(dir, "mockup_walk --seconds 1 --object-up 1,0,0 --no-reacquire");
  INFO(wrong["loop"].dump());
  const int frames = wrong["frames"].get<int>();
  REQUIRE(frames >= 20);
  CHECK(wrong["loop"]["deadlines"]["acquisition"]["against_gravity"].get<int>() == frames);
  CHECK(wrong["loop"]["predictor"]["vision_against_gravity"].get<int>() == frames);
  CHECK(wrong["loop"]["tracked"].get<int>() == 0);
  CHECK(wrong["tracking_success"].get<double>() == 0.0);
  const auto right = sim_run_summary(dir, "mockup_walk --seconds 1 --object-up 0,0,1 --no-reacquire");
  INFO(right["loop"].dump());
  CHECK(right["loop"]["deadlines"]["acquisition"]["against_gravity"].get<int>() == 0);
  CHECK(right["tracking_success"].get<double>() >= 0.99);
}

// Coming back (issue 22 item 5). Without vision the filter's tilt is updated from the
// accelerometer and its position held near the last one vision verified (fusion/unaided_update.h),
// and over the gap it no longer integrates the last reading's acceleration: the prediction is
// upright and in place again, and the tracker re-locks from it. Before, the prediction stayed 23
// deg off (the tracker could not lock from the attitude it coasted to).
TEST_CASE("sim-run --soak: after a bus-off inside a step's burst the tracker and the prediction come back to the truth",
          "[tools][sim-run][soak]") {
  TempDir dir("sim_run_bus_off_drift");
  const BusOffRun run = run_bus_off(dir);
  INFO(run.summary["soak"].dump());
  // Measured (seed 1): 1.3 deg early, 0.61 deg over the last second (23 deg before the unaided
  // updates of fusion/unaided_update.h).
  CHECK(run.summary["soak"]["predicted_attitude_error_deg_median_late"].get<double>() < 3.0);
}

TEST_CASE("sim-run leaves the frames a cover board hides the object in out of the tracking success, as score does",
          "[tools][sim-run]") {
  TempDir dir("sim_run_cover");
  const std::string scn = dir.write("cover.scn", slurp(std::string(EPICHEAD_SOURCE_DIR) + "/sim/scenarios/mockup_walk.scn") +
                                                     "cover 1.0 0.5\n");
  const auto r = run_epichead(dir, "sim-run '" + scn + "' --out '" + dir.str() + "/out' --seconds 2 --downscale 4 --every 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(slurp(dir / "out/summary.json"));
  INFO(j.dump());
  // The 0.5 s the board stands still at the scenario's frame rate, and the part of each 0.3 s
  // slide in which it already (still) fills the view; not the whole slides.
  const int hidden = j["hidden_frames"].get<int>();
  CHECK(hidden >= 15);
  CHECK(hidden < 15 + 18);
  CHECK(j["frames"].get<int>() > 20);
  CHECK(r.out.find("frames with the object hidden by a cover left out") != std::string::npos);
}

TEST_CASE("sim-run: gated poses that agree restart the predictor, as in track (fusion/vision_arbiter.h)", "[tools][sim-run]") {
  TempDir dir("sim_run_arbiter");
  // box_clutter, seed 2: at 1.7-1.8 s the predictor gates three poses that agree with each other;
  // the third restarts it from vision. Without the arbiter the filter gated 8 poses by 2 s and
  // re-initialised itself once.
  // No re-acquisition: nothing is lost in these 2 s, and its templates need not be built here.
  const auto j = sim_run_summary(dir, "box_clutter --seed 2 --seconds 2 --no-reacquire");
  const auto& p = j["loop"]["predictor"];
  INFO(p.dump());
  CHECK(p["restarts_after_agreeing_gated"].get<int>() == 1);
  CHECK(p["restarts_after_supported_gated"].get<int>() == 0);
  CHECK(p["restarts_from_fallback"].get<int>() == 0);
  CHECK(p["reinitialisations"].get<int>() == 1);  // the restart, no re-initialisation besides
  CHECK(p["vision_gated"].get<int>() < 8);
}

TEST_CASE("sim-run: a frame the predictor's pose loses is measured again from the vision poses extrapolated alone, as in track", "[tools][sim-run]") {
  TempDir dir("sim_run_fallback");
  // can, seed 2: past 7 s the predictor's pose leaves the can on a frame where the vision poses'
  // own extrapolation still finds it. Without that second opinion (before 2026-12-07) the loop
  // tracked 91.1 % of the first 7.5 s; with it 96.1 %, from one frame so measured.
  // As measured then, without re-acquisition (the can's templates are not built here).
  const auto j = sim_run_summary(dir, "can --seed 2 --seconds 7.5 --no-reacquire");
  INFO(j["loop"].dump());
  CHECK(j["loop"]["fallback_frames"].get<int>() >= 1);
  CHECK(j["tracking_success"].get<double>() >= 0.95);
}

TEST_CASE("sim-run finds the object again by detection after a loss by default as run does, and not when told not to or downscaled",
          "[tools][sim-run]") {
  TempDir dir("sim_run_reacquire");
  // box_cover: a board hides the package from 2.5 to 3.5 s. The templates (--views 1, the
  // simulator's camera) are the ones the "package templates" fixture put in the test cache.
  const auto r = run_epichead(dir, "sim-run box_cover --seconds 4.5 --views 1 --every 0 --out '" + dir.str() + "/on'");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto on = nlohmann::json::parse(slurp(dir / "on/summary.json"));
  const auto& acq = on["loop"]["deadlines"]["acquisition"];
  INFO(acq.dump());
  CHECK(on["reacquire"] == true);
  CHECK(acq["losses"].get<int>() >= 1);
  CHECK(acq["detections"].get<int>() >= 1);
  CHECK(acq["reacquisitions"].get<int>() >= 1);
  CHECK(r.out.find("re-acquisition on: ") != std::string::npos);
  CHECK(on["tracking_success"].get<double>() >= 0.95);

  // Told not to, or with a camera smaller than the templates': no detection, and the line says why.
  for (const auto& [flags, why] : {std::pair<std::string, std::string>{"--no-reacquire", "--no-reacquire"},
                                   {"--downscale 2", "detection needs --downscale 1"}}) {
    const auto off = run_epichead(dir, "sim-run box_cover --seconds 0.5 --every 0 " + flags + " --out '" + dir.str() + "/off'");
    INFO(off.out << off.err);
    REQUIRE(off.exit_code == 0);
    const auto j = nlohmann::json::parse(slurp(dir / "off/summary.json"));
    CHECK(j["reacquire"] == false);
    CHECK(j["loop"]["deadlines"]["acquisition"]["detections"] == 0);
    CHECK(off.out.find("re-acquisition off (" + why + ")") != std::string::npos);
  }
  // Asked for with a downscaled camera: an error naming why, before anything runs.
  const auto bad = run_epichead(dir, "sim-run box_cover --seconds 0.5 --reacquire --downscale 2 --out '" + dir.str() + "/bad'");
  CHECK(bad.exit_code == 1);
  CHECK(bad.err.find("need the full-size camera (--downscale 1)") != std::string::npos);
  const auto both = run_epichead(dir, "sim-run box_cover --reacquire --no-reacquire --out '" + dir.str() + "/both'");
  CHECK(both.exit_code != 0);
  CHECK(both.err.find("--reacquire excludes --no-reacquire") != std::string::npos);
  // Without a start pose the loop detects, after a loss too: --no-reacquire cannot hold then.
  const auto no_init = run_epichead(dir, "sim-run box_cover --no-init --no-reacquire --out '" + dir.str() + "/no_init'");
  CHECK(no_init.exit_code != 0);
  CHECK(no_init.err.find("excludes") != std::string::npos);
  CHECK(no_init.err.find("--no-init") != std::string::npos);
}

TEST_CASE("timeline.csv's header is the list of columns README.md documents, each named with its unit") {
  TempDir dir("sim_run_timeline");
  const auto r = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() +
                                       "/out' --seconds 0.3 --mode stabilise --downscale 8 --every 0 --settle-s 0");
  INFO(r.out << r.err);
  REQUIRE(r.exit_code == 0);
  const auto header = lines_of(slurp(dir / "out/timeline.csv")).at(0);
  const auto documented = epichead::testing::documented_columns(EPICHEAD_SOURCE_DIR "/README.md", "**timeline.csv**");
  CHECK(header == epichead::testing::joined(documented));
  // SI or named with the unit: time in s, the rest with a unit suffix.
  for (const std::string& column : documented) {
    INFO(column);
    CHECK((column.ends_with("_s") || column.ends_with("_deg") || column.ends_with("_degps") || column.ends_with("_px")));
  }
}
