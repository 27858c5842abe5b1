// `epichead track` on a held-out draw of a body of revolution: a lampshade simulated with a seed
// no parameter was tuned on, tracked with the IMU, names the axis whose turn its edges cannot
// show, scores within 5 cm / 5 deg once that turn is removed, and feeds the filter vision
// updates; --free-turn off still tracks, --object-up gives the gravity check its down from the
// first frame, and a bad --free-turn value is refused.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/run_tool.h"
#include "common/temp_dir.h"

using epichead::testing::run_epichead;
using epichead::testing::slurp;
using epichead::testing::TempDir;

namespace {
namespace fs = std::filesystem;
const auto& q = epichead::testing::shell_quoted;
}  // namespace

TEST_CASE("track --imu on follows a held-out lampshade, names its free turn's axis and scores with the turn removed") {
  TempDir tmp("epichead_test_track_heldout");
  const std::string seq = tmp / "lampshade-13", out = tmp / "track";
  const auto sim = run_epichead(tmp, "sim lampshade --out " + q(seq) + " --frames 30 --seed 13");
  INFO(sim.err);
  REQUIRE(sim.exit_code == 0);
  const auto run = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " --imu on --every 0 --no-video");
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const auto report = nlohmann::json::parse(slurp(out + "/report.json"));
  CHECK(report["frames"] == 30);

  // The lampshade is modelled about its z axis: the axis the tracker leaves free is that one.
  REQUIRE(report.contains("free_turn_axis"));
  const auto& axis = report["free_turn_axis"];
  INFO(axis.dump());
  const auto& dir = axis["direction_obj"];
  REQUIRE(dir.size() == 3);
  CHECK(std::abs(dir[0].get<double>()) < 1e-6);
  CHECK(std::abs(dir[1].get<double>()) < 1e-6);
  CHECK(std::abs(dir[2].get<double>()) == Approx(1.0).epsilon(1e-9));
  const auto& point = axis["point_obj"];
  REQUIRE(point.size() == 3);
  CHECK(std::hypot(point[0].get<double>(), point[1].get<double>()) < 1e-6);  // on the z axis

  // The filter took vision updates and measured their consistency.
  const auto& nis = report["predictor"]["vision_nis"];
  INFO(nis.dump());
  CHECK(nis["count"].get<int>() > 0);
  // Each compared in the five directions vision measures, the turn about the axis left out
  // (fusion/free_direction.h).
  CHECK(nis["mean_dof"].get<double>() == Approx(5.0));

  const auto score = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --sym-axis 0,0,1 --json");
  INFO(score.err);
  REQUIRE(score.exit_code == 0);
  const auto s = nlohmann::json::parse(score.out);
  INFO(s.dump());
  CHECK(s["frames"] == 30);
  CHECK(s["success_rate"].get<double>() >= 0.97);

  // With the free turn off the same sequence still tracks (the facets then fix the turn), and
  // the report names no free axis.
  const std::string off = tmp / "track_off";
  const auto fixed = run_epichead(tmp, "track " + q(seq) + " --out " + q(off) + " --imu on --free-turn off --every 0 --no-video");
  INFO(fixed.err);
  REQUIRE(fixed.exit_code == 0);
  const auto off_report = nlohmann::json::parse(slurp(off + "/report.json"));
  CHECK(off_report["frames"] == 30);
  CHECK_FALSE(off_report.contains("free_turn_axis"));

  // Told the shade's up, the filter checks tilts against it from the first frame (30 frames are
  // too few to learn a down: 30 applied poses in a row are needed) and still tracks.
  CHECK_FALSE(report["predictor"]["gravity_told"].get<bool>());
  const std::string told = tmp / "track_told";
  const auto up = run_epichead(tmp, "track " + q(seq) + " --out " + q(told) + " --imu on --object-up 0,0,1 --every 0 --no-video");
  INFO(up.err);
  REQUIRE(up.exit_code == 0);
  const auto told_report = nlohmann::json::parse(slurp(told + "/report.json"));
  const auto& predictor = told_report["predictor"];
  INFO(predictor.dump());
  CHECK(predictor["gravity_told"].get<bool>());
  REQUIRE(predictor["learnt_down_obj"].size() == 3);
  CHECK(predictor["learnt_down_obj"][2].get<double>() == Approx(-1.0));
  std::size_t checked = 0;
  for (const auto& f : told_report["per_frame"]) checked += f["tilt_error_deg"].is_number();
  CHECK(checked >= 25);
  const auto told_score = run_epichead(tmp, "score " + q(seq) + " " + q(told + "/poses.csv") + " --sym-axis 0,0,1 --json");
  REQUIRE(told_score.exit_code == 0);
  CHECK(nlohmann::json::parse(told_score.out)["success_rate"].get<double>() >= 0.97);
}

TEST_CASE("track refuses a --free-turn value other than auto or off with one line naming the option") {
  TempDir tmp("epichead_test_track_heldout");
  const std::string data = std::string(EPICHEAD_SHARED_DATA) + "/teabox";
  const auto r = run_epichead(tmp, "track " + q(data) + " --out " + q(tmp / "x") + " --free-turn bogus");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--free-turn") != std::string::npos);
  CHECK(r.err.find("bogus") != std::string::npos);
  CHECK_FALSE(fs::exists(tmp / "x/report.json"));
}

TEST_CASE("a lampshade filmed through a fisheye lens (a cv::fisheye calibration) is simulated and tracked through it") {
  TempDir tmp("epichead_test_track_fisheye");
  // The lampshade scenario with a wide fisheye camera: rays 60 deg off the axis reach the corners.
  {
    std::ifstream in(std::string(EPICHEAD_SOURCE_DIR) + "/sim/scenarios/lampshade.scn");
    std::ofstream out(tmp / "fisheye.scn");
    for (std::string line; std::getline(in, line);) out << (line.starts_with("camera ") ? "camera fisheye.yaml" : line) << "\n";
    std::ofstream(tmp / "fisheye.yaml")
        << "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\nfisheye_model: 1\n"
           "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 400., 0., 319.5, 0., 400., 239.5, 0., 0., 1. ]\n"
           "distortion_coefficients: !!opencv-matrix\n   rows: 4\n   cols: 1\n   dt: d\n   data: [ 0.02, -0.01, 0.003, -0.0005 ]\n";
  }
  const std::string seq = tmp / "seq", out = tmp / "track";
  const auto sim = run_epichead(tmp, "sim " + q(tmp / "fisheye.scn") + " --out " + q(seq) + " --frames 30");
  INFO(sim.err);
  REQUIRE(sim.exit_code == 0);
  CHECK(slurp(seq + "/camera.yaml").find("fisheye_model: 1") != std::string::npos);
  const auto run = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " --every 0 --no-video");
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const auto score = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --sym-axis 0,0,1 --json");
  REQUIRE(score.exit_code == 0);
  const auto s = nlohmann::json::parse(score.out);
  INFO(s.dump());
  CHECK(s["success_rate"].get<double>() >= 0.97);
  // The model lands on the image's edges to a fraction of a pixel: projected as the lens bends.
  CHECK(s["reprojection_px"]["median"].get<double>() < 0.5);
}
