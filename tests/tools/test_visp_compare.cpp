// `epichead-visp` (ViSP's model-based tracker on our sequences) through the built program, on
// the real teabox video. The program is optional (built only when ViSP is installed): without it
// every test here passes with a warning that it was skipped.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "common/temp_dir.h"
#include "epichead/vision/offline/stamped_pose.h"

using namespace epichead::vision;

namespace {

namespace fs = std::filesystem;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_visp_compare") {}
};

// epichead-visp is written next to epichead (same runtime output directory).
std::string visp_bin() { return (fs::path(EPICHEAD_BIN).parent_path() / "epichead-visp").string(); }

bool visp_built() { return fs::exists(visp_bin()); }

#define SKIP_WITHOUT_VISP()                                                          \
  do {                                                                               \
    if (!visp_built()) {                                                             \
      WARN("skipped: " << visp_bin() << " not built (ViSP / libvisp-dev not found)"); \
      return;                                                                        \
    }                                                                                \
  } while (0)

struct Run {
  int exit_code = -1;
  std::string out, err;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string q(const std::string& s) { return "'" + s + "'"; }

Run run_visp(const TempDir& tmp, const std::string& args) {
  const std::string out = tmp / "stdout.txt", err = tmp / "stderr.txt";
  const std::string command = q(visp_bin()) + " " + args + " > " + q(out) + " 2> " + q(err);
  const int status = std::system(command.c_str());
  Run r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

const std::string kTeabox = std::string(EPICHEAD_SHARED_DATA) + "/teabox";

// A copy of teabox (files linked) whose init.csv is `init`.
std::string teabox_with_init(const TempDir& tmp, const StampedPose& init) {
  const fs::path dir = tmp.path / "teabox";
  fs::create_directories(dir);
  for (const char* name : {"camera.yaml", "model.cao", "video.mp4"}) fs::create_symlink(fs::path(kTeabox) / name, dir / name);
  REQUIRE(write_pose_csv((dir / "init.csv").string(), {init}));
  return dir.string();
}

double rotation_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

}  // namespace

TEST_CASE("epichead-visp --help succeeds and a bad command line is one line and a non-zero exit") {
  SKIP_WITHOUT_VISP();
  TempDir tmp;
  const Run help = run_visp(tmp, "--help");
  CHECK(help.exit_code == 0);
  CHECK(help.out.find("--mode") != std::string::npos);

  const Run bad_mode = run_visp(tmp, q(kTeabox) + " --out " + q(tmp / "o") + " --mode corners");
  CHECK(bad_mode.exit_code != 0);
  CHECK(bad_mode.err.find("--mode 'corners'") != std::string::npos);
  CHECK(std::count(bad_mode.err.begin(), bad_mode.err.end(), '\n') == 1);

  const Run no_out = run_visp(tmp, q(kTeabox));
  CHECK(no_out.exit_code != 0);
  CHECK(std::count(no_out.err.begin(), no_out.err.end(), '\n') == 1);
}

TEST_CASE("epichead-visp names the missing file of a broken sequence and exits non-zero") {
  SKIP_WITHOUT_VISP();
  TempDir tmp;
  const Run missing = run_visp(tmp, q(tmp / "nowhere") + " --out " + q(tmp / "o"));
  CHECK(missing.exit_code != 0);
  CHECK(missing.err.find("nowhere") != std::string::npos);

  // A model ViSP cannot parse is an error naming the file, not a crash.
  const fs::path dir = tmp.path / "badmodel";
  fs::create_directories(dir);
  for (const char* name : {"camera.yaml", "video.mp4", "init.csv"}) fs::create_symlink(fs::path(kTeabox) / name, dir / name);
  tmp.write("badmodel/model.cao", "V1\n8\n0 0 0\n");
  const Run bad_model = run_visp(tmp, q(dir.string()) + " --out " + q(tmp / "o2"));
  CHECK(bad_model.exit_code != 0);
  CHECK(bad_model.err.find("model.cao") != std::string::npos);
}

TEST_CASE("epichead-visp tracks the teabox video in every frame and agrees with the peer's ViSP poses") {
  SKIP_WITHOUT_VISP();
  TempDir tmp;
  const std::string out = tmp / "out";
  const Run run = run_visp(tmp, q(kTeabox) + " --out " + q(out) + " --mode edges+klt --overlay-every 20");
  REQUIRE(run.exit_code == 0);

  auto poses = read_pose_csv(out + "/poses.csv");
  REQUIRE(poses);
  auto reference = read_pose_csv(kTeabox + "/reference_visp.csv");
  REQUIRE(reference);
  REQUIRE(poses->size() == reference->size());  // one row per frame of the video
  for (std::size_t i = 0; i < poses->size(); ++i) {
    const auto& p = (*poses)[i];
    const auto& r = (*reference)[i];
    INFO("frame " << p.frame);
    CHECK(p.frame == r.frame);
    CHECK(p.status == "tracked");
    // The peer ran the same tracker on the same video: a few mm and tenths of a degree apart.
    CHECK((p.cam_T_obj.translation() - r.cam_T_obj.translation()).norm() < 0.01);
    CHECK(rotation_deg(p.cam_T_obj, r.cam_T_obj) < 1.5);
  }

  const auto report = nlohmann::json::parse(slurp(out + "/report.json"));
  CHECK(report.at("frames") == 39);
  CHECK(report.at("tracked") == 39);
  CHECK(report.at("lost") == 0);
  CHECK(report.at("mode") == "edges+klt");
  CHECK(report.at("track_ms_median").get<double>() > 0);
  CHECK(report.at("track_ms_p99").get<double>() >= report.at("track_ms_median").get<double>());
  CHECK(report.at("per_frame").size() == 39);
  CHECK(fs::exists(out + "/overlay_000000.png"));
  CHECK(fs::exists(out + "/overlay_000020.png"));
  CHECK_FALSE(fs::exists(out + "/overlay_000010.png"));
}

TEST_CASE("epichead-visp reports lost frames and keeps writing poses when started far from the object") {
  SKIP_WITHOUT_VISP();
  TempDir tmp;
  auto init = read_pose_csv(kTeabox + "/init.csv");
  REQUIRE(init);
  StampedPose wrong = init->front();
  // Turned by 60 degrees about the camera's optical axis: no model edge is near an image edge
  // of the right orientation.
  wrong.cam_T_obj.linear() = Eigen::AngleAxisd(60.0 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) * wrong.cam_T_obj.linear();
  const std::string seq = teabox_with_init(tmp, wrong);
  const std::string out = tmp / "out";
  const Run run = run_visp(tmp, q(seq) + " --out " + q(out) + " --mode edges");
  REQUIRE(run.exit_code == 0);
  auto poses = read_pose_csv(out + "/poses.csv");
  REQUIRE(poses);
  CHECK(poses->size() == 39);
  int lost = 0;
  for (const auto& p : *poses) lost += p.status == "lost";
  CHECK(lost > 0);
  const auto report = nlohmann::json::parse(slurp(out + "/report.json"));
  CHECK(report.at("lost") == lost);
  CHECK(report.at("tracked").get<int>() + lost == 39);
}
