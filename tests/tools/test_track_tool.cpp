// `epichead track` end to end: a short simulated mockup_walk sequence tracked to its success
// target and scored, the real teabox video against its hand-read corners, and the errors a user
// meets first.
#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "common/per_frame_scores.h"
#include "common/run_tool.h"
#include "common/temp_dir.h"

using epichead::testing::frame_successes;
using epichead::testing::run_epichead;
using epichead::testing::slurp;
using epichead::testing::TempDir;

namespace {
namespace fs = std::filesystem;
const auto& q = epichead::testing::shell_quoted;

// report.json of `track SEQ --out OUT ARGS`, which must succeed.
nlohmann::json track_report(const TempDir& tmp, const std::string& seq, const std::string& out, const std::string& args) {
  const auto run = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " " + args);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  return nlohmann::json::parse(slurp(out + "/report.json"));
}
}  // namespace

TEST_CASE("track follows a short simulated mockup_walk with epic+validation and writes every output") {
  TempDir tmp("epichead_test_track_tool");
  const std::string seq = tmp / "mockup_walk", out = tmp / "track";
  REQUIRE(run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 40").exit_code == 0);
  const auto report = track_report(tmp, seq, out, "--every 20");
  CHECK(report["frames"] == 40);
  CHECK(report["tracked"].get<int>() + report["lost"].get<int>() == 40);
  // The target (>= 99 % on mockup_walk at the default jerk) is measured on the full
  // sequence by tools/results.sh; in these 40 frames one step burst may outrun the windows
  // without IMU prediction (it is then reported lost, and re-acquired on the next frame).
  CHECK(report["lost"].get<int>() <= 1);
  CHECK(report["track_ms_median"].get<double>() > 0);
  // The worst frame beside the median and p99 (a start, or preemption; docs/performance.md), and
  // it is the largest of the frames' own times.
  CHECK(report["track_ms_p99"].get<double>() >= report["track_ms_median"].get<double>());
  CHECK(report["track_ms_max"].get<double>() >= report["track_ms_p99"].get<double>());
  double worst = 0;
  for (const auto& f : report["per_frame"]) worst = std::max(worst, f["ms"]["total"].get<double>());
  CHECK(report["track_ms_max"].get<double>() == worst);
  CHECK(report["per_frame"].size() == 40);
  CHECK(report["per_frame"][5]["lines"]["visible"].get<int>() >= 25);
  CHECK(fs::exists(out + "/overlay_000000.png"));
  CHECK(fs::exists(out + "/overlay_000020.png"));
  CHECK(fs::exists(out + "/overlay_000039.png"));
  CHECK(fs::exists(out + "/overlay.mp4"));

  const auto score = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --json");
  REQUIRE(score.exit_code == 0);
  const auto s = nlohmann::json::parse(score.out);
  // At most the burst's lost frame and the frame it is re-locked in (the re-lock lands within
  // a few tenths of the 5 deg bound or just beyond it, depending on the start's last digits).
  CHECK(s["success_rate"].get<double>() >= 0.95);
  CHECK(s["rotation_deg"]["median"].get<double>() < 1.0);
  CHECK(s["translation_mm"]["median"].get<double>() < 10.0);

  // The covariance the tracker gives the filter, checked against the truth.
  const auto checked = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --json --covariance " +
                                             q(out + "/vision_covariance.csv"));
  INFO(checked.err);
  REQUIRE(checked.exit_code == 0);
  const auto c = nlohmann::json::parse(checked.out)["covariance_consistency"];
  CHECK(c["dof"] == 6);
  CHECK(c["count"].get<int>() >= 36);
  // Honest within a factor of a few here (docs/fusion.md gives the figures per scenario).
  CHECK(c["scale_for_mean"].get<double>() > 0.2);
  CHECK(c["scale_for_mean"].get<double>() < 5.0);
}

TEST_CASE("track's report says which start a start frame kept and why a rim was not found") {
  TempDir tmp("epichead_test_track_start_report");
  const std::string seq = tmp / "can", out = tmp / "track";
  REQUIRE(run_epichead(tmp, "sim can --out " + q(seq) + " --frames 8").exit_code == 0);
  const auto frames = track_report(tmp, seq, out, "--every 0 --no-video")["per_frame"];
  REQUIRE(frames.size() == 8);
  // Frame 0 is a start from init.csv: the settle's choice and both supports.
  const auto& start = frames[0]["start"];
  REQUIRE(start.is_object());
  const auto& given = start["support_given"];
  const auto& gradient = start["support_gradient_pass"];
  if (start["kept"] == "gradient_pass") {
    // Kept only when usable and at least as well supported as the given start's measurement.
    REQUIRE(gradient.is_number());
    if (given.is_number()) CHECK(gradient.get<double>() >= given.get<double>());
  } else {
    CHECK(start["kept"] == "given");
    if (given.is_number() && gradient.is_number()) CHECK(given.get<double>() > gradient.get<double>());
  }
  // A frame after a tracked one is no start.
  if (frames[0]["status"] != "lost") CHECK_FALSE(frames[1].contains("start"));
  // Every visible rim is found or refused for one reason.
  for (const auto& f : frames) {
    const auto& e = f["ellipses"];
    int refused = 0;
    for (const char* why : {"no_candidate", "leaves_window", "other_shape", "few_lines"}) refused += e["refused"][why].get<int>();
    INFO("frame " << f["frame"]);
    CHECK(refused == e["visible"].get<int>() - e["found"].get<int>());
  }
  CHECK(frames[3]["ellipses"]["visible"].get<int>() == 2);  // the can's two rims
}

TEST_CASE("track --imu on finds the IMU clock offset from the gyro and the tracked poses (auto) and tracks every frame") {
  TempDir tmp("epichead_test_track_offset");
  const std::string seq = tmp / "mockup_walk", out = tmp / "track";
  // 3 s: two step bursts, enough turning for the fit (1.5 s of poses at least).
  REQUIRE(run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 90").exit_code == 0);
  const auto run = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " --imu on --every 0 --no-video");
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const auto report = nlohmann::json::parse(slurp(out + "/report.json"));
  const auto truth = nlohmann::json::parse(slurp(seq + "/sim_truth.json"));
  const auto& est = report["predictor"]["imu_time_offset_estimate"];
  INFO(est.dump());
  REQUIRE(est["adopted"].get<bool>());
  CHECK(report["predictor"]["imu_time_offset_s"].get<double>() ==
        Approx(truth["imu"]["clock_offset_s"].get<double>()).margin(0.003));
  CHECK(report["lost"].get<int>() == 0);
  CHECK(run.out.find("camera-IMU time offset estimated: ") != std::string::npos);  // the user is told
  // A given offset is used as it is, and nothing is said about it.
  const auto fixed = run_epichead(tmp, "track " + q(seq) + " --out " + q(tmp / "fixed") + " --imu on --imu-time-offset-s 0.01 --every 0 --no-video");
  REQUIRE(fixed.exit_code == 0);
  const auto fr = nlohmann::json::parse(slurp(tmp / "fixed/report.json"));
  CHECK(fr["predictor"]["imu_time_offset_s"].get<double>() == 0.01);
  CHECK(fr["predictor"]["imu_time_offset_estimate"].is_null());
  CHECK(fr["predictor"]["imu_time_offset_sigma_s"].get<double>() == 0);  // a given offset is exact unless told otherwise
  CHECK(fixed.out.find("time offset") == std::string::npos);
  CHECK(fixed.err.find("time offset") == std::string::npos);
  // Too short a run to estimate it: said on stderr, with the way out.
  const auto brief = run_epichead(tmp, "track " + q(seq) + " --out " + q(tmp / "brief") + " --imu on --frames 20 --every 0 --no-video");
  REQUIRE(brief.exit_code == 0);
  CHECK(brief.err.find("time offset could not be estimated") != std::string::npos);
  CHECK(brief.err.find("needed") != std::string::npos);  // which bar it missed
  CHECK(nlohmann::json::parse(slurp(tmp / "brief/report.json"))["predictor"]["imu_time_offset_sigma_s"].get<double>() == 0.01);
  // A given offset known to a few milliseconds: the poses carry that doubt.
  const auto loose = run_epichead(tmp, "track " + q(seq) + " --out " + q(tmp / "loose") +
                                           " --imu on --imu-time-offset-s 0.01 --imu-time-offset-sigma-s 0.004 --frames 20 --every 0 --no-video");
  REQUIRE(loose.exit_code == 0);
  CHECK(nlohmann::json::parse(slurp(tmp / "loose/report.json"))["predictor"]["imu_time_offset_sigma_s"].get<double>() == 0.004);
  const auto wide = run_epichead(tmp, "track " + q(seq) + " --out " + q(tmp / "wide") + " --imu on --imu-time-offset-sigma-s 0.5 --every 0 --no-video");
  CHECK(wide.exit_code != 0);
  CHECK(wide.err.find("--imu-time-offset-sigma-s") != std::string::npos);
  CHECK(brief.err.find("--imu-time-offset-s") != std::string::npos);
}

TEST_CASE("track --imu on writes the filter's estimate, which rides out the poses of blurred shakes") {
  // box_clutter at twice its jerk: a 170 deg/s shake at 1.2 s blurs the box, and a pose from its
  // few lines can be degrees off; the filter weighs it against the gyro.
  TempDir tmp("epichead_test_track_fused");
  const std::string seq = tmp / "box_clutter", out = tmp / "track";
  REQUIRE(run_epichead(tmp, "sim box_clutter --out " + q(seq) + " --frames 75 --jerk 2").exit_code == 0);
  const auto truth = nlohmann::json::parse(slurp(seq + "/sim_truth.json"));
  const std::string offset = std::to_string(truth["imu"]["clock_offset_s"].get<double>());
  const auto report = track_report(tmp, seq, out, "--imu on --imu-time-offset-s " + offset + " --every 0 --no-video");
  CHECK(report["fused_frames"].get<int>() == 75 - report["lost"].get<int>());
  auto score = [&](const std::string& poses) {
    const auto r = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/" + poses) + " --json");
    REQUIRE(r.exit_code == 0);
    return nlohmann::json::parse(r.out);
  };
  const auto fused = score("poses.csv"), vision = score("vision_poses.csv");
  INFO("fused " << fused.dump() << "\nvision " << vision.dump());
  CHECK(fused["success_rate"].get<double>() == 1.0);
  CHECK(fused["success_rate"].get<double>() >= vision["success_rate"].get<double>());
  CHECK(fused["rotation_deg"]["p95"].get<double>() < 0.75 * vision["rotation_deg"]["p95"].get<double>());
  // Once the object's down is learnt (30 applied poses in a row), each tracked frame says how far
  // its pose tilts the object from the accelerometer's down: a fraction of a degree when right.
  std::vector<double> tilts;
  for (const auto& f : report["per_frame"])
    if (f.contains("tilt_error_deg")) {
      CHECK(f["frame"].get<int>() >= 30);
      tilts.push_back(f["tilt_error_deg"].get<double>());
    }
  REQUIRE(tilts.size() >= 20);
  std::nth_element(tilts.begin(), tilts.begin() + tilts.size() / 2, tilts.end());
  CHECK(tilts[tilts.size() / 2] < 1.0);
  // Each frame the filter was given says what it did; the counts agree with the predictor's.
  int applied = 0, gated = 0, restarts = 0, given = 0, strong = 0;
  for (const auto& f : report["per_frame"]) {
    if (!f.contains("filter")) {
      CHECK(f["status"] == "lost");
      continue;
    }
    ++given;
    const auto& v = f["filter"];
    applied += v["verdict"] == "applied";
    gated += v["verdict"] == "gated";
    restarts += !v["restart"].is_null();
    if (v["verdict"] == "applied" || v["verdict"] == "gated") CHECK(v["nis"].get<double>() >= 0);
    // What the arbiter read of the pose's support; a clean run's poses are nearly all strong.
    strong += v["strongly_supported"].get<bool>();
  }
  CHECK(strong > 50);
  const auto& p = report["predictor"];
  CHECK(given == 75 - report["lost"].get<int>());
  CHECK(applied == p["vision_applied"].get<int>());
  CHECK(gated <= p["vision_gated"].get<int>());
  CHECK(restarts == p["restarts_from_fallback"].get<int>() + p["restarts_after_supported_gated"].get<int>() +
                        p["restarts_after_agreeing_gated"].get<int>());
  CHECK(applied > 50);
}

TEST_CASE("track --imu on does not give a filter seeded out of view a chance lock its spread prediction made") {
  // late_entry seed 276: init.csv's pose with the object out of view until frame 24; the filter,
  // carried by the IMU alone with its velocity unknown, predicts the object 245 px (1-sigma)
  // from nowhere in particular, and the tracker re-locks there on part of the object, 7 deg and
  // 196 mm off. Applied, that lock held the run at 0 % (the twin after it, at 180 deg).
  TempDir tmp("epichead_test_track_unplaceable");
  const std::string seq = tmp / "late_entry", out = tmp / "track";
  REQUIRE(run_epichead(tmp, "sim late_entry --seed 276 --out " + q(seq) + " --frames 60").exit_code == 0);
  // --no-reacquire: detection would build the package's templates (minutes under the sanitizers).
  const auto report = track_report(tmp, seq, out, "--imu on --no-reacquire --every 0 --no-video");
  CHECK(report["predictor"]["weak_poses_unplaceable"].get<int>() > 0);
  // Until the first pose the image supports well, no pose reaches the filter.
  bool strong_seen = false;
  for (const auto& f : report["per_frame"]) {
    if (!f.contains("filter")) continue;
    const auto& v = f["filter"];
    strong_seen = strong_seen || v["strongly_supported"].get<bool>();
    if (!strong_seen) {
      INFO("frame " << f["frame"] << " " << v.dump());
      CHECK(v["verdict"] == "held-weak-unplaceable");
      CHECK(v["predicted_sigma_px"].get<double>() > 40);
    }
  }
  CHECK(strong_seen);
  const auto r = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --json");
  REQUIRE(r.exit_code == 0);
  const auto score = nlohmann::json::parse(r.out);
  INFO(score.dump());
  // Every frame the object is in view (from 24 on) within 5 cm / 5 deg; it was none.
  CHECK(score["present"].get<int>() >= 30);
  CHECK(score["succeeded"].get<int>() >= score["present"].get<int>() - 1);
}

TEST_CASE("track --imu on keeps init.csv's pose as the seed when the first frame's pose moved far from it") {
  // stumble seed 287: from init.csv's pose (within a centimetre and a degree of the truth) the
  // tracker locks 66 mm and 7 deg off on the first frame. Seeded from that lock, the filter held
  // the windows there: none of the first 40 frames within 5 cm / 5 deg (89 % without the IMU).
  TempDir tmp("epichead_test_track_start_pose");
  const std::string seq = tmp / "stumble", out = tmp / "track";
  REQUIRE(run_epichead(tmp, "sim stumble --seed 287 --out " + q(seq)).exit_code == 0);
  const auto report = track_report(tmp, seq, out, "--imu on --no-reacquire --every 0 --no-video --frames 40");
  CHECK(report["per_frame"][0]["filter"]["verdict"] == "held-against-start-pose");
  CHECK(report["predictor"]["poses_against_start_pose"].get<int>() == 1);
  const auto r = run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --json");
  REQUIRE(r.exit_code == 0);
  const auto score = nlohmann::json::parse(r.out);
  INFO(score.dump());
  CHECK(score["present"].get<int>() == 40);
  CHECK(score["succeeded"].get<int>() >= 39);
}

TEST_CASE("track --imu on keeps the gyro's turn while the object is out of view, and finds it where the turn brings it") {
  // late_entry: init.csv's pose with the object out of view; the robot turns onto it after 1.2 s.
  // --no-reacquire: detection would build the package's templates (minutes under the sanitizers),
  // so what is checked is the prediction alone.
  TempDir tmp("epichead_test_track_carried_turn");
  const auto scored = [&](int seed) {
    const std::string seq = tmp / ("late_entry_" + std::to_string(seed)), out = tmp / ("track_" + std::to_string(seed));
    REQUIRE(run_epichead(tmp, "sim late_entry --seed " + std::to_string(seed) + " --out " + q(seq) + " --frames 70").exit_code == 0);
    const auto report = track_report(tmp, seq, out, "--imu on --no-reacquire --every 0 --no-video");
    REQUIRE(run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --per-frame " + q(out + "/f.csv")).exit_code == 0);
    // frame -> rotation error (deg), for the frames with a pose
    std::map<int, double> rotation_deg;
    std::ifstream in(out + "/f.csv");
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      std::stringstream row(line);
      std::string frame, present, success, rot;
      std::getline(row, frame, ',');
      std::getline(row, present, ',');
      std::getline(row, success, ',');
      std::getline(row, rot, ',');
      if (present == "1") rotation_deg[std::stoi(frame)] = std::stod(rot);
    }
    return std::pair{report, rotation_deg};
  };
  {
    // Seed 278: the package comes into view at frame 29, 0.9 s after init.csv's pose. The filter
    // lost nothing for 1 s counted from that pose (it was counted from time 0, and the filter was
    // forgotten just before): it places the windows on the package, and every frame with a pose is
    // right. Before, no frame had one.
    const auto [report, rotation_deg] = scored(278);
    INFO(report["predictor"].dump());
    CHECK(rotation_deg.size() >= 35);
    const auto score = nlohmann::json::parse(run_epichead(tmp, "score " + q(tmp / "late_entry_278") + " " + q(tmp / "track_278/poses.csv") + " --json").out);
    CHECK(score["succeeded"].get<int>() >= score["present"].get<int>() - 1);
  }
  {
    // Seed 280: out of view for longer than a second, so the filter is forgotten. The prediction
    // is then the last good pose turned as the gyro turned the camera: the tracker finds the
    // package, half of its 30 poses turned within 5 deg of the truth (their distance, from a part
    // of the package at the border, is off by 20-25 cm). Before, the pose as it was left the
    // windows beside the view, and no frame had a pose.
    const auto [report, rotation_deg] = scored(280);
    INFO(report["predictor"].dump());
    CHECK(report["predictor"]["resets_after_loss"].get<int>() >= 1);
    CHECK(report["predictor"]["fallbacks_to_last_pose"].get<int>() > 0);
    int turned_right = 0;
    for (const auto& [frame, deg] : rotation_deg) turned_right += deg < 5.0;
    CHECK(turned_right >= 10);
  }
}

TEST_CASE("track without the IMU follows a hand-held burst by the frame's own motion, which constant velocity misses") {
  TempDir tmp("epichead_test_track_image_motion");
  const std::string seq = tmp / "box_clutter";
  // Development seed 6 of box_clutter (the first 50 frames of a 100-frame draw): a shake from
  // frame 30 moves the package 20-40 px a frame. Detection is off, so each run shows what the
  // prediction alone does.
  REQUIRE(run_epichead(tmp, "sim box_clutter --seed 6 --out " + q(seq) + " --frames 100").exit_code == 0);
  const auto successes = [&](const std::string& name, const std::string& flags) {
    const std::string out = tmp / name;
    const auto r = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " --frames 50 --imu off --no-reacquire --every 0 --no-video" + flags);
    INFO(r.out << r.err);
    REQUIRE(r.exit_code == 0);
    REQUIRE(run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --per-frame " + q(out + "/f.csv")).exit_code == 0);
    return frame_successes(out + "/f.csv");
  };
  const auto shake_ok = [](const auto& scored) {
    int ok = 0;
    for (int f = 30; f <= 36; ++f) ok += scored.at(f);
    return ok;
  };
  // By default: every frame within the bounds but a blurred one or two (builds round differently),
  // the prediction turned where it missed.
  const auto followed = successes("image_motion", "");
  int all_ok = 0;
  for (const auto& [frame, success] : followed) all_ok += frame < 50 && success;
  CHECK(all_ok >= 48);
  const auto report = nlohmann::json::parse(slurp(tmp / "image_motion/report.json"));
  INFO(report["image_motion"].dump());
  CHECK(report["lost"].get<int>() == 0);
  CHECK(report["image_motion"]["measured_frames"].get<int>() == 49);  // every frame after the first
  CHECK(report["image_motion"]["corrected_predictions"].get<int>() >= 3);
  CHECK(report["per_frame"][31].contains("image_motion"));
  // Constant velocity alone loses the package in the shake.
  CHECK(shake_ok(successes("constant_velocity", " --image-motion off")) <= 3);
  CHECK(shake_ok(followed) >= 6);
}

TEST_CASE("track follows the real teabox video to within a few pixels of the hand-read corners") {
  TempDir tmp("epichead_test_track_tool");
  const std::string data = std::string(EPICHEAD_SHARED_DATA) + "/teabox", out = tmp / "teabox";
  const auto report = track_report(tmp, data, out, "--every 0 --no-video");
  CHECK(report["lost"] == 0);
  const auto score = run_epichead(tmp, "score " + q(data) + " " + q(out + "/poses.csv") + " --json --reference " +
                                           q(data + "/reference_visp.csv") + " --corners 0:" +
                                           q(data + "/corners_frame000.txt") + " --corners 38:" +
                                           q(data + "/corners_frame038.txt"));
  INFO(score.err);
  REQUIRE(score.exit_code == 0);
  const auto s = nlohmann::json::parse(score.out);
  CHECK(s["success_rate"].get<double>() == 1.0);  // within 5 cm / 5 deg of the peer's poses
  for (const auto& c : s["corners"]) {
    CHECK(c["present"] == true);
    CHECK(c["rms_px"].get<double>() < 8.0);  // hand-read to +-2..3 px
  }
}

TEST_CASE("track rejects bad arguments with one line and a non-zero exit") {
  TempDir tmp("epichead_test_track_tool");
  const std::string data = std::string(EPICHEAD_SHARED_DATA) + "/teabox";
  auto r = run_epichead(tmp, "track " + q(data) + " --out " + q(tmp / "x") + " --mode sharpest");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--mode") != std::string::npos);
  r = run_epichead(tmp, "track " + q(tmp / "missing") + " --out " + q(tmp / "x"));
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("missing") != std::string::npos);
  r = run_epichead(tmp, "track " + q(data) + " --out " + q(tmp / "x") + " --imu on");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("imu.csv") != std::string::npos);
  r = run_epichead(tmp, "track " + q(data) + " --out " + q(tmp / "x") + " --imu-time-offset-s soon");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("'auto' or seconds") != std::string::npos);
  r = run_epichead(tmp, "track " + q(data) + " --out " + q(tmp / "x") + " --image-motion sometimes");
  CHECK(r.exit_code != 0);
  CHECK(r.err.find("--image-motion must be auto, on or off") != std::string::npos);
  r = run_epichead(tmp, "track --help");
  CHECK(r.exit_code == 0);
  CHECK(r.out.find("--mode") != std::string::npos);
}

TEST_CASE("track --imu on gives frames vision loses the filter's propagation, status predicted, for --coast-s after its last pose") {
  TempDir tmp("epichead_test_track_coast");
  const std::string seq = tmp / "mockup_walk";
  REQUIRE(run_epichead(tmp, "sim mockup_walk --out " + q(seq) + " --frames 40").exit_code == 0);
  // Frames 20 and 21 show nothing (a dropped exposure): vision loses both.
  const cv::Mat frame = cv::imread(seq + "/frames/000020.png");
  REQUIRE(!frame.empty());
  for (const char* name : {"/frames/000020.png", "/frames/000021.png"})
    REQUIRE(cv::imwrite(seq + name, cv::Mat(frame.size(), frame.type(), cv::Scalar::all(90))));
  const std::string offset =
      std::to_string(nlohmann::json::parse(slurp(seq + "/sim_truth.json"))["imu"]["clock_offset_s"].get<double>());
  // Each frame's status and whether it is within the bounds.
  struct Frame {
    std::string status;
    bool success = false;
  };
  const auto run = [&](const std::string& name, const std::string& coast) {
    const std::string out = tmp / name;
    // --no-reacquire: this is about the filter's propagation; a detection's recheck of the
    // frames after the gap would build the mockup's templates (two minutes under the sanitizers).
    const auto r = run_epichead(tmp, "track " + q(seq) + " --out " + q(out) + " --imu on --imu-time-offset-s " + offset +
                                         " --every 0 --no-video --no-reacquire" + coast);
    INFO(r.out << r.err);
    REQUIRE(r.exit_code == 0);
    REQUIRE(run_epichead(tmp, "score " + q(seq) + " " + q(out + "/poses.csv") + " --per-frame " + q(out + "/f.csv")).exit_code == 0);
    std::vector<Frame> frames(40);
    std::ifstream poses(out + "/poses.csv");
    std::string line;
    std::getline(poses, line);
    while (std::getline(poses, line)) frames.at(static_cast<std::size_t>(std::stoi(line))).status = line.substr(line.rfind(',') + 1);
    for (const auto& [frame, success] : frame_successes(out + "/f.csv")) frames.at(static_cast<std::size_t>(frame)).success = success;
    const auto report = nlohmann::json::parse(slurp(out + "/report.json"));
    CHECK(report["lost"].get<int>() >= 2);
    return std::make_pair(frames, report["predicted_frames"].get<int>());
  };
  // By default (0.2 s): both lost frames are the IMU's propagation, and right.
  const auto [coasted, predicted] = run("default", "");
  CHECK(coasted[19].status == "tracked");
  CHECK(coasted[20].status == "predicted");
  CHECK(coasted[21].status == "predicted");
  CHECK(coasted[20].success);
  CHECK(coasted[21].success);
  CHECK(coasted[22].status == "tracked");
  CHECK(predicted == 2);
  // Half a frame time past the last pose: the first only.
  const auto [short_coast, short_predicted] = run("short", " --coast-s 0.05");
  CHECK(short_coast[20].status == "predicted");
  CHECK(short_coast[21].status == "lost");
  CHECK_FALSE(short_coast[21].success);
  CHECK(short_predicted == 1);
  // Off: lost, as without the IMU.
  const auto [off, off_predicted] = run("off", " --coast-s 0");
  CHECK(off[20].status == "lost");
  CHECK(off[21].status == "lost");
  CHECK(off_predicted == 0);
}
