// `epichead sim-run` end to end (issue 9, items 4-5): the closed loop stabilises the camera
// against the fixed head, writes its summary, timeline, plots and a bus log that `epichead
// replay` reads, and rejects bad input with one line.
#include <catch2/catch.hpp>

#include <filesystem>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "common/run_tool.h"
#include "common/temp_dir.h"

using epichead::testing::run_epichead;
using epichead::testing::slurp;
using epichead::testing::TempDir;

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

TEST_CASE("sim-run rejects bad input with one line naming the reason", "[tools][sim-run]") {
  TempDir dir("sim_run_bad");
  const auto mode = run_epichead(dir, "sim-run mockup_walk --out '" + dir.str() + "/o' --mode dance");
  CHECK(mode.exit_code != 0);
  CHECK(mode.err.find("--mode must be fixate, stabilise or hold") != std::string::npos);
  const auto scn = run_epichead(dir, "sim-run no_such_scene --out '" + dir.str() + "/o'");
  CHECK(scn.exit_code != 0);
  CHECK(scn.err.find("no_such_scene") != std::string::npos);
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
  // 0.5 s at the scenario's frame rate, give or take a frame at either end.
  const int hidden = j["hidden_frames"].get<int>();
  CHECK(hidden >= 12);
  CHECK(hidden <= 17);
  CHECK(j["frames"].get<int>() > 20);
  CHECK(r.out.find("frames with the object hidden by a cover left out") != std::string::npos);
}
