// `epichead score` through the built program, on a tiny synthetic image sequence of a cube.
#include <catch2/catch.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "epichead/vision/offline/pose_covariance_csv.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "epichead/vision/visibility.h"
#include "common/run_tool.h"

using namespace epichead::vision;

namespace {

namespace fs = std::filesystem;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_score_tool") {}
};

using epichead::testing::slurp;
using Run = epichead::testing::ToolRun;

// Runs `epichead score <args>` (arguments already shell-quoted) and captures both streams.
Run score(const TempDir& tmp, const std::string& args) { return epichead::testing::run_epichead(tmp, "score " + args); }

const auto& q = epichead::testing::shell_quoted;

StampedPose pose_at(int frame) {
  StampedPose p;
  p.frame = frame;
  p.t_s = frame / 30.0;
  p.cam_T_obj = Eigen::Translation3d(0.005 * frame, 0.01, 0.5) * Eigen::AngleAxisd(0.4 + 0.05 * frame, Eigen::Vector3d(1, 1, 0).normalized());
  return p;
}

constexpr int kFrames = 5;

// camera.yaml, model.cao (a cube), five PNG frames with frames.csv, init.csv and gt.csv.
std::string make_sequence(const TempDir& tmp, bool with_gt = true) {
  const fs::path dir = tmp.path / "seq";
  fs::create_directories(dir / "frames");
  const std::string fixtures = std::string(EPICHEAD_TEST_DATA) + "/seq";
  fs::copy_file(fixtures + "/camera.yaml", dir / "camera.yaml");
  fs::copy_file(fixtures + "/cube.cao", dir / "model.cao");
  std::vector<FrameEntry> frames;
  std::vector<StampedPose> gt;
  for (int i = 0; i < kFrames; ++i) {
    const std::string name = "frames/" + std::to_string(i) + ".png";
    REQUIRE(cv::imwrite((dir / name).string(), cv::Mat(120, 160, CV_8UC3, cv::Scalar(20 * i, 100, 200))));
    frames.push_back({i, i / 30.0, name});
    gt.push_back(pose_at(i));
  }
  REQUIRE(write_frames_csv((dir / "frames.csv").string(), frames).has_value());
  REQUIRE(write_pose_csv((dir / "init.csv").string(), {gt[0]}).has_value());
  if (with_gt) REQUIRE(write_pose_csv((dir / "gt.csv").string(), gt).has_value());
  return dir.string();
}

// Ground truth shifted by 20 mm, with frame 2 missing.
std::string make_estimates(const TempDir& tmp) {
  std::vector<StampedPose> est;
  for (int i = 0; i < kFrames; ++i) {
    if (i == 2) continue;
    StampedPose p = pose_at(i);
    p.cam_T_obj.translation().x() += 0.020;
    p.status = "tracked";
    est.push_back(p);
  }
  const std::string path = tmp / "poses.csv";
  REQUIRE(write_pose_csv(path, est).has_value());
  return path;
}

bool one_line(const std::string& s, const std::string& prefix) {
  return s.rfind(prefix, 0) == 0 && s.find('\n') == s.size() - 1;
}

}  // namespace

TEST_CASE("score --json prints one object with counts, rate, losses and error statistics") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  const Run r = score(tmp, q(seq) + " " + q(make_estimates(tmp)) + " --json");
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j.at("frames") == kFrames);
  CHECK(j.at("present") == kFrames - 1);
  CHECK(j.at("succeeded") == kFrames - 1);
  CHECK(j.at("success_rate").get<double>() == Approx(0.8));
  CHECK(j.at("losses") == 1);
  for (const char* key : {"rotation_deg", "translation_mm", "reprojection_px"})
    for (const char* stat : {"mean", "median", "p95"}) CHECK(j.at(key).at(stat).is_number());
  CHECK(j.at("translation_mm").at("mean").get<double>() == Approx(20.0).epsilon(1e-6));
  CHECK(j.at("rotation_deg").at("p95").get<double>() == Approx(0).margin(1e-5));
  CHECK(j.at("reprojection_px").at("median").get<double>() > 1.0);
}

TEST_CASE("score prints a human summary by default") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  const Run r = score(tmp, q(seq) + " " + q(make_estimates(tmp)));
  REQUIRE(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("success rate") && Catch::Contains("80.0 %") && Catch::Contains("losses") &&
                        Catch::Contains("translation_mm") && Catch::Contains("20.000"));
  CHECK(r.err.empty());
}

TEST_CASE("score --per-frame writes one row per ground-truth frame") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  const Run r = score(tmp, q(seq) + " " + q(make_estimates(tmp)) + " --per-frame " + q(tmp / "per_frame.csv"));
  REQUIRE(r.exit_code == 0);
  std::ifstream in(tmp / "per_frame.csv");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  REQUIRE(lines.size() == kFrames + 1);
  CHECK(lines[0] ==
        "frame,present,success,rotation_deg,translation_mm,reprojection_px,err_tx_m,err_ty_m,err_tz_m,err_rx_rad,"
        "err_ry_rad,err_rz_rad");
  CHECK(lines[3] == "2,0,0,,,,,,,,,");
  // 20 mm off along x: truth = exp(err) * estimate moves it back.
  CHECK_THAT(lines[1], Catch::StartsWith("0,1,1,") && Catch::Contains(",20.000000,") && Catch::Contains(",-0.020000,"));

  const Run bad = score(tmp, q(seq) + " " + q(make_estimates(tmp)) + " --per-frame " + q(tmp / "no/such/dir.csv"));
  CHECK(bad.exit_code == 1);
  CHECK(one_line(bad.err, "epichead score: "));
}

TEST_CASE("score --per-frame with --covariance gives each scored frame's NEES") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  // 10 mm and 1 mrad sigmas: the 20 mm error along x is two sigmas, NEES 4.
  std::vector<StampedCovariance> covs;
  for (int i = 0; i < kFrames; ++i) {
    if (i == 2) continue;
    StampedCovariance c;
    c.frame = i;
    c.t_s = i / 30.0;
    c.covariance.setZero();
    c.covariance.diagonal() << 1e-4, 1e-4, 1e-4, 1e-6, 1e-6, 1e-6;
    covs.push_back(c);
  }
  REQUIRE(write_pose_covariance_csv(tmp / "cov.csv", covs).has_value());
  const Run r = score(tmp, q(seq) + " " + q(make_estimates(tmp)) + " --json --covariance " + q(tmp / "cov.csv") +
                               " --per-frame " + q(tmp / "per_frame.csv"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(nlohmann::json::parse(r.out).at("covariance_consistency").at("mean").get<double>() == Approx(4.0).epsilon(1e-3));
  std::ifstream in(tmp / "per_frame.csv");
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  REQUIRE(lines.size() == kFrames + 1);
  CHECK_THAT(lines[0], Catch::EndsWith(",err_rz_rad,nees"));
  CHECK_THAT(lines[1], Catch::EndsWith(",4.000000"));
  CHECK_THAT(lines[3], Catch::StartsWith("2,0,0,") && Catch::EndsWith(","));
}

TEST_CASE("score --sym-axis removes the turn about the given axis") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  std::vector<StampedPose> est;
  for (int i = 0; i < kFrames; ++i) {
    StampedPose p = pose_at(i);
    p.cam_T_obj = p.cam_T_obj * Eigen::AngleAxisd(50 * std::numbers::pi / 180, Eigen::Vector3d::UnitY());
    est.push_back(p);
  }
  REQUIRE(write_pose_csv(tmp / "turned.csv", est).has_value());
  const Run plain = score(tmp, q(seq) + " " + q(tmp / "turned.csv") + " --json");
  REQUIRE(plain.exit_code == 0);
  CHECK(nlohmann::json::parse(plain.out).at("succeeded") == 0);
  const Run sym = score(tmp, q(seq) + " " + q(tmp / "turned.csv") + " --json --sym-axis 0,2,0");
  REQUIRE(sym.exit_code == 0);
  const auto j = nlohmann::json::parse(sym.out);
  CHECK(j.at("succeeded") == kFrames);
  CHECK(j.at("rotation_deg").at("mean").get<double>() == Approx(0).margin(1e-5));
}

TEST_CASE("score refuses a sequence without gt.csv") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp, false);
  const Run r = score(tmp, q(seq) + " " + q(make_estimates(tmp)));
  CHECK(r.exit_code == 1);
  CHECK(r.err == "epichead score: " + seq + " has no gt.csv (no ground truth to score against); give --reference or --corners\n");
  CHECK(r.out.empty());
}

TEST_CASE("score reports bad input in one line and exits non-zero") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  const std::string poses = make_estimates(tmp);
  for (const char* axis : {"1,2", "a,b,c", "0,0,0", "1,2,3,4", "1,nan,0", "1,2,"}) {
    INFO("axis " << axis);
    const Run r = score(tmp, q(seq) + " " + q(poses) + " --sym-axis " + q(axis));
    CHECK(r.exit_code == 1);
    CHECK(one_line(r.err, "epichead score: --sym-axis '" + std::string(axis) + "'"));
  }
  {
    std::ofstream(tmp / "broken.csv") << "frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,1,1,0,0,0\n1,0.1,0,0,one,1,0,0,0\n";
    const Run r = score(tmp, q(seq) + " " + q(tmp / "broken.csv"));
    CHECK(r.exit_code == 1);
    CHECK(r.err == "epichead score: " + (tmp / "broken.csv") + ":3: tz is not a number ('one')\n");
  }
  {
    const Run r = score(tmp, q(tmp / "nowhere") + " " + q(poses));
    CHECK(r.exit_code == 1);
    CHECK(one_line(r.err, "epichead score: " + (tmp / "nowhere")));
  }
  {
    fs::remove(fs::path(seq) / "frames/3.png");
    const Run r = score(tmp, q(seq) + " " + q(poses));
    CHECK(r.exit_code == 1);
    CHECK(one_line(r.err, "epichead score: " + seq + "/frames/3.png: frame file not found"));
  }
}

TEST_CASE("score --help describes the command and exits 0") {
  TempDir tmp;
  const Run r = score(tmp, "--help");
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.out, Catch::Contains("--sym-axis") && Catch::Contains("--per-frame") && Catch::Contains("--json"));
}

TEST_CASE("score --lines counts a selection right on the true edge and wrong when it is a parallel line 10 px away") {
  TempDir tmp;
  const std::string seq_dir = make_sequence(tmp);
  auto seq = Sequence::open(seq_dir);
  REQUIRE(seq);
  // For every visible cube edge: the true projection (right) in even frames, the same line
  // moved 10 px sideways (wrong) in odd frames.
  Visibility visibility(seq->model(), seq->camera());
  VisibleModel vis;
  std::ofstream lines(tmp / "lines.csv");
  lines << "frame,edge,found,candidates,a_x,a_y,b_x,b_y,inlier\n";
  int even = 0, odd = 0;
  for (int i = 0; i < kFrames; ++i) {
    visibility.compute(pose_at(i).cam_T_obj, vis);
    for (const auto& e : vis.edges) {
      Eigen::Vector2d n(-(e.b_px - e.a_px).y(), (e.b_px - e.a_px).x());
      n.normalize();
      const Eigen::Vector2d shift = i % 2 ? Eigen::Vector2d(10 * n) : Eigen::Vector2d::Zero();
      lines << i << ',' << e.edge << ",1,2," << (e.a_px + shift).x() << ',' << (e.a_px + shift).y() << ','
            << (e.b_px + shift).x() << ',' << (e.b_px + shift).y() << ",1\n";
      (i % 2 ? odd : even) += 1;
    }
  }
  lines.close();
  REQUIRE(even > 0);
  REQUIRE(odd > 0);
  const Run r = score(tmp, q(seq_dir) + " " + q(make_estimates(tmp)) + " --json --lines " + q(tmp / "lines.csv"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto ls = nlohmann::json::parse(r.out).at("line_selection");
  CHECK(ls.at("selections") == even + odd);
  CHECK(ls.at("right_rate").get<double>() == Approx(static_cast<double>(even) / (even + odd)));

  std::ofstream(tmp / "bad.csv") << "frame,edge\n1,2\n";
  const Run bad = score(tmp, q(seq_dir) + " " + q(make_estimates(tmp)) + " --lines " + q(tmp / "bad.csv"));
  CHECK(bad.exit_code != 0);
  CHECK(bad.err.find("bad.csv") != std::string::npos);
}

TEST_CASE("score leaves out the frames a cover hides the object in (sim_truth.json), unless --include-hidden, and refuses a bad run naming the file") {
  TempDir tmp;
  const std::string seq = make_sequence(tmp);
  const std::string poses = make_estimates(tmp);  // frame 2 has no estimate
  {
    std::ofstream truth(seq + "/sim_truth.json");
    truth << R"({"scenario": "test", "object_hidden_frames": [[2, 2]]})";
  }
  const Run r = score(tmp, q(seq) + " " + q(poses) + " --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const auto j = nlohmann::json::parse(r.out);
  CHECK(j.at("hidden_frames") == 1);
  CHECK(j.at("hidden_reported_tracked") == 0);
  CHECK(j.at("frames") == kFrames - 1);
  CHECK(j.at("success_rate").get<double>() == Approx(1.0));
  CHECK(j.at("losses") == 0);
  CHECK(j.at("ignored") == 0);

  const Run all = score(tmp, q(seq) + " " + q(poses) + " --json --include-hidden");
  REQUIRE(all.exit_code == 0);
  const auto k = nlohmann::json::parse(all.out);
  CHECK(k.at("hidden_frames") == 0);
  CHECK(k.at("frames") == kFrames);
  CHECK(k.at("success_rate").get<double>() == Approx(0.8));

  // An estimate that claims to track a hidden frame is counted.
  {
    std::ofstream truth(seq + "/sim_truth.json");
    truth << R"({"object_hidden_frames": [[3, 4]]})";
  }
  const Run claimed = score(tmp, q(seq) + " " + q(poses) + " --json");
  REQUIRE(claimed.exit_code == 0);
  CHECK(nlohmann::json::parse(claimed.out).at("hidden_reported_tracked") == 2);

  for (const char* bad : {R"({"object_hidden_frames": [[4, 2]]})", R"({"object_hidden_frames": [["a", 2]]})", "{\"object_hidden"}) {
    std::ofstream(seq + "/sim_truth.json") << bad;
    const Run e = score(tmp, q(seq) + " " + q(poses) + " --json");
    INFO(bad << " -> " << e.err);
    CHECK(e.exit_code != 0);
    CHECK(e.err.find("sim_truth.json") != std::string::npos);
  }
}
