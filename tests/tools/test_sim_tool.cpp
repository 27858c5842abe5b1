#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <sys/wait.h>
#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "epichead/vision/offline/sequence.h"

namespace fs = std::filesystem;

namespace {

struct Run {
  int code = -1;
  std::string out, err;
};

// One folder for the test process, removed when it ends.
fs::path scratch() {
  static const epichead::testing::TempDir dir("epichead_test_sim_tool");
  return dir.path;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Run run(const std::string& args) {
  const fs::path out = scratch() / "stdout.txt", err = scratch() / "stderr.txt";
  const std::string cmd = std::string("'") + EPICHEAD_BIN + "' sim " + args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  Run r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// Relative path -> content of every file under dir.
std::map<std::string, std::string> tree(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = slurp(e.path());
  return files;
}

}  // namespace

TEST_CASE("sim --help names the options", "[tools][sim]") {
  const Run r = run("--help");
  CHECK(r.code == 0);
  CHECK(r.out.find("--jerk") != std::string::npos);
  CHECK(r.out.find("mockup_walk") != std::string::npos);
}

TEST_CASE("sim writes a sequence that Sequence::open reads, with gt, perturbed init and device-time IMU",
          "[tools][sim]") {
  const fs::path seq = scratch() / "walk";
  const Run r = run("mockup_walk --out '" + seq.string() + "' --frames 3 --jerk 1.5");
  INFO(r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("wrote " + seq.string()) != std::string::npos);
  CHECK(r.out.find("3 frames") != std::string::npos);
  CHECK(r.out.find("peak body angular rate") != std::string::npos);
  auto s = epichead::vision::Sequence::open(seq.string());
  INFO((s ? "" : s.error()));
  REQUIRE(s);
  CHECK(s->frame_count() == 3);
  REQUIRE(s->has_ground_truth());
  REQUIRE(s->ground_truth().size() == 3);
  REQUIRE(s->has_imu());
  auto image = s->read_frame(2);
  REQUIRE(image);
  CHECK(image->cols == 640);
  CHECK(image->rows == 480);
  // init.csv is the frame-0 truth moved by about 1 cm and 1 degree.
  const Eigen::Isometry3d& gt0 = s->ground_truth()[0].cam_T_obj;
  const Eigen::Isometry3d& init = s->init().cam_T_obj;
  CHECK((gt0.translation() - init.translation()).norm() == Approx(0.01).epsilon(0.01));
  CHECK(Eigen::AngleAxisd(gt0.linear().transpose() * init.linear()).angle() * 180 / 3.14159265358979 ==
        Approx(1.0).epsilon(0.01));
  CHECK(s->ground_truth()[1].t_s - s->ground_truth()[0].t_s == Approx(1.0 / 30));
  CHECK(s->frames()[1].t_s == s->ground_truth()[1].t_s);
  // gt projects the model into the image.
  int inside = 0;
  for (const auto& v : s->model().vertices) {
    const Eigen::Vector3d p = gt0 * v;
    inside += p.z() > 0 && s->camera().in_image(s->camera().project(p));
  }
  CHECK(inside >= 0.8 * static_cast<double>(s->model().vertices.size()));
  // imu.csv holds device time stamps (offset 13.7 ms, 40 ppm in mockup_walk.scn); imu_true.csv the true time.
  auto truth = epichead::vision::read_imu_csv((seq / "imu_true.csv").string());
  REQUIRE(truth);
  REQUIRE(!truth->empty());
  CHECK(truth->front().t_s == Approx(0.0).margin(1e-3));
  CHECK(s->imu().front().t_s == Approx(0.014).margin(1e-9));
  CHECK(truth->size() >= s->imu().size());
  // At 1 kHz on the device clock, covering the frames.
  CHECK(s->imu()[1].t_s - s->imu()[0].t_s == Approx(1e-3));
  CHECK(truth->back().t_s > s->ground_truth().back().t_s);
  CHECK(fs::exists(seq / "sim_truth.json"));
  CHECK(slurp(seq / "scenario.scn").find("scene mockup_walk") != std::string::npos);
}

TEST_CASE("sim output is byte-identical for a seed and differs for another seed", "[tools][sim]") {
  const fs::path a = scratch() / "a", b = scratch() / "b", c = scratch() / "c";
  REQUIRE(run("box_clutter --out '" + a.string() + "' --frames 5 --seed 11").code == 0);
  REQUIRE(run("box_clutter --out '" + b.string() + "' --frames 5 --seed 11").code == 0);
  REQUIRE(run("box_clutter --out '" + c.string() + "' --frames 5 --seed 12").code == 0);
  const auto ta = tree(a), tb = tree(b), tc = tree(c);
  CHECK(ta.size() >= 12);
  REQUIRE(ta.size() == tb.size());
  for (const auto& [name, content] : ta) {
    INFO(name);
    CHECK(tb.count(name) == 1);
    CHECK(tb.at(name) == content);
  }
  CHECK(tc.at("init.csv") != ta.at("init.csv"));
  CHECK(tc.at("imu.csv") != ta.at("imu.csv"));
  CHECK(tc.at("frames/000004.png") != ta.at("frames/000004.png"));
  // Re-running into an earlier output replaces it (fewer frames leave no stale images).
  REQUIRE(run("box_clutter --out '" + a.string() + "' --frames 2 --seed 11").code == 0);
  CHECK(!fs::exists(a / "frames" / "000004.png"));
}

TEST_CASE("sim: --seed alone draws a new scene (variety 1), --variety 0 keeps the built-in one", "[tools][sim]") {
  const fs::path a = scratch() / "va", b = scratch() / "vb", c = scratch() / "vc";
  REQUIRE(run("can --out '" + a.string() + "' --frames 1 --seed 11").code == 0);
  REQUIRE(run("can --out '" + b.string() + "' --frames 1 --seed 11 --variety 0").code == 0);
  REQUIRE(run("can --out '" + c.string() + "' --frames 1 --variety 0.5").code == 0);
  const std::string ja = slurp(a / "sim_truth.json"), jb = slurp(b / "sim_truth.json"), jc = slurp(c / "sim_truth.json");
  CHECK(ja.find("\"scene_variety\": {\n    \"variety\": 1,") != std::string::npos);
  CHECK(ja.find("\"plane_textures\"") != std::string::npos);
  // can.scn has a cover window, so its draws are recorded even at variety 0.
  CHECK(jb.find("\"variety\": 0,") != std::string::npos);
  CHECK(jc.find("\"variety\": 0.5,") != std::string::npos);
  CHECK(run("can --out '" + c.string() + "' --frames 1 --variety 2").code != 0);
}

TEST_CASE("sim rejects bad input with one line naming the reason", "[tools][sim]") {
  const auto one_line = [](const Run& r) {
    CHECK(r.code != 0);
    CHECK(r.err.rfind("epichead sim: ", 0) == 0);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  };
  const fs::path out = scratch() / "bad";
  Run r = run("no_such_scenario --out '" + out.string() + "'");
  one_line(r);
  CHECK(r.err.find("no_such_scenario") != std::string::npos);

  r = run("office_pan --out '" + out.string() + "' --jerk 2");
  one_line(r);
  CHECK(r.err.find("wheeled") != std::string::npos);

  const fs::path scn = scratch() / "broken.scn";
  std::ofstream(scn) << "scene box_clutter\nframes 3\nmotion handheld\nsway_hz lots\n";
  r = run("'" + scn.string() + "' --out '" + out.string() + "'");
  one_line(r);
  CHECK(r.err.find(scn.string() + ":4: ") != std::string::npos);

  const fs::path precious = scratch() / "precious";
  fs::create_directories(precious);
  std::ofstream(precious / "notes.txt") << "keep me\n";
  r = run("box_clutter --out '" + precious.string() + "' --frames 1");
  one_line(r);
  CHECK(slurp(precious / "notes.txt") == "keep me\n");

  r = run("box_clutter --out '" + out.string() + "' --frames 0");
  CHECK(r.code != 0);
}
