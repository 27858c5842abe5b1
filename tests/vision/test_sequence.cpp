// Sequence directories: the two real video sequences, a synthetic image sequence written and
// read back, and the errors a user meets (missing frame files, malformed rows, bad video).
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/offline/sequence.h"
#include "common/temp_dir.h"

using namespace epichead::vision;

namespace {

namespace fs = std::filesystem;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_sequence") {}
};

const std::string kShared = EPICHEAD_SHARED_DATA;
const std::string kFixtures = std::string(EPICHEAD_TEST_DATA) + "/seq";

// A distinct, easily checked picture per frame.
cv::Mat frame_image(int i) {
  cv::Mat image(120, 160, CV_8UC3, cv::Scalar(10 * i, 255 - 10 * i, 40));
  cv::rectangle(image, cv::Rect(5 * i, 10, 20, 30), cv::Scalar(255, 255, 255), cv::FILLED);
  return image;
}

StampedPose pose_at(int frame) {
  StampedPose p;
  p.frame = frame;
  p.t_s = frame / 30.0;
  p.cam_T_obj = Eigen::Translation3d(0.01 * frame, -0.02, 0.6) *
                Eigen::AngleAxisd(0.05 * frame + 0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized());
  return p;
}

// A complete image sequence of `n` frames: camera, cube, init, gt, imu, frames.csv and PNGs.
void write_image_sequence(const TempDir& dir, int n) {
  fs::copy_file(kFixtures + "/camera.yaml", dir.path / "camera.yaml");
  fs::copy_file(kFixtures + "/cube.cao", dir.path / "model.cao");
  REQUIRE(write_pose_csv(dir.str() + "/init.csv", {pose_at(0)}).has_value());
  std::vector<StampedPose> gt;
  std::vector<FrameEntry> frames;
  fs::create_directories(dir.path / "frames");
  for (int i = 0; i < n; ++i) {
    gt.push_back(pose_at(i));
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", i);
    frames.push_back({i, i / 30.0, name});
    REQUIRE(cv::imwrite(dir.str() + "/" + name, frame_image(i)));
  }
  REQUIRE(write_pose_csv(dir.str() + "/gt.csv", gt).has_value());
  REQUIRE(write_frames_csv(dir.str() + "/frames.csv", frames).has_value());
  std::vector<ImuRecord> imu;
  for (int k = 0; k < 4 * n; ++k)
    imu.push_back({k / 120.0, Eigen::Vector3d(0.1 * k, -0.2, 1.0 / 3.0), Eigen::Vector3d(0.05, 9.81, -0.1 * k)});
  REQUIRE(write_imu_csv(dir.str() + "/imu.csv", imu).has_value());
}

std::string open_error(const TempDir& dir) {
  auto seq = Sequence::open(dir.str());
  REQUIRE_FALSE(seq.has_value());
  return seq.error();
}

void check_real_sequence(const std::string& name, std::size_t frames) {
  auto seq = Sequence::open(kShared + "/" + name);
  REQUIRE(seq.has_value());
  REQUIRE(seq->frame_count() == frames);
  CHECK_FALSE(seq->has_ground_truth());
  CHECK_FALSE(seq->has_imu());
  CHECK(seq->model().vertices.size() == 8);
  CHECK(seq->camera().width_px() == 640);
  CHECK(seq->init().frame == 0);
  CHECK(seq->frames().back().frame == static_cast<int>(frames) - 1);
  CHECK(seq->frames()[10].t_s == Approx(10 / 25.0));  // 25 fps
  CHECK(seq->frames()[10].file.empty());
  for (std::size_t i = 0; i < seq->frame_count(); ++i) {
    auto image = seq->read_frame(i);
    REQUIRE(image.has_value());
    CHECK(image->cols == 640);
    CHECK(image->rows == 480);
  }
  auto past_end = seq->read_frame(frames);
  REQUIRE_FALSE(past_end.has_value());
  CHECK_THAT(past_end.error(), Catch::Contains("out of range"));
}

}  // namespace

TEST_CASE("the teabox sequence opens and all 39 video frames decode to 640x480") { check_real_sequence("teabox", 39); }

TEST_CASE("the teabox_left sequence opens and all 121 video frames decode to 640x480") {
  check_real_sequence("teabox_left", 121);
}

TEST_CASE("reading video frames out of order gives the same pictures as reading in order") {
  auto seq = Sequence::open(kShared + "/teabox");
  REQUIRE(seq.has_value());
  std::vector<cv::Mat> in_order;
  for (std::size_t i = 0; i < 12; ++i) in_order.push_back(seq->read_frame(i).value());
  for (std::size_t i : {7u, 2u, 3u, 11u, 0u, 0u, 5u}) {
    auto image = seq->read_frame(i);
    REQUIRE(image.has_value());
    CHECK(cv::norm(*image, in_order[i], cv::NORM_INF) == 0);
  }
  // The pictures do change over the clip, so the comparison above can tell frames apart.
  CHECK(cv::norm(in_order[0], in_order[11], cv::NORM_L1) > 0);
}

TEST_CASE("a synthetic image sequence round-trips through the sequence files") {
  TempDir dir;
  write_image_sequence(dir, 6);
  auto seq = Sequence::open(dir.str());
  REQUIRE(seq.has_value());
  CHECK(seq->dir() == dir.str());
  CHECK(seq->camera().width_px() == 160);
  CHECK(seq->model().faces.size() == 6);
  REQUIRE(seq->frame_count() == 6);
  REQUIRE(seq->has_ground_truth());
  REQUIRE(seq->ground_truth().size() == 6);
  for (int i = 0; i < 6; ++i) {
    const FrameEntry& f = seq->frames()[static_cast<std::size_t>(i)];
    CHECK(f.frame == i);
    CHECK(f.t_s == i / 30.0);
    const StampedPose& g = seq->ground_truth()[static_cast<std::size_t>(i)];
    CHECK(g.t_s == i / 30.0);
    CHECK((g.cam_T_obj.matrix() - pose_at(i).cam_T_obj.matrix()).norm() < 1e-8);
  }
  CHECK((seq->init().cam_T_obj.matrix() - pose_at(0).cam_T_obj.matrix()).norm() < 1e-8);
  REQUIRE(seq->has_imu());
  REQUIRE(seq->imu().size() == 24);
  CHECK(seq->imu()[7].t_s == 7 / 120.0);
  CHECK(seq->imu()[7].gyro_radps == Eigen::Vector3d(0.1 * 7, -0.2, 1.0 / 3.0));
  CHECK(seq->imu()[7].accel_mps2 == Eigen::Vector3d(0.05, 9.81, -0.1 * 7));
  for (std::size_t i : {3u, 0u, 5u}) {
    auto image = seq->read_frame(i);
    REQUIRE(image.has_value());
    CHECK(cv::norm(*image, frame_image(static_cast<int>(i)), cv::NORM_INF) == 0);
  }
}

TEST_CASE("a sequence can be moved and still reads its frames") {
  TempDir dir;
  write_image_sequence(dir, 2);
  auto opened = Sequence::open(dir.str());
  REQUIRE(opened.has_value());
  Sequence seq = std::move(*opened);
  CHECK(seq.read_frame(1).has_value());
}

TEST_CASE("a missing frame file is reported when the sequence opens") {
  TempDir dir;
  write_image_sequence(dir, 5);
  fs::remove(dir.path / "frames/000003.png");
  fs::remove(dir.path / "frames/000004.png");
  const std::string error = open_error(dir);
  CHECK_THAT(error, Catch::Contains("frames/000003.png") && Catch::Contains("not found"));
  CHECK_THAT(error, !Catch::Contains("000004"));  // the first missing one
}

TEST_CASE("a corrupt image is an error value from read_frame that names the file") {
  TempDir dir;
  write_image_sequence(dir, 3);
  dir.write("frames/000001.png", "\x89PNG\r\n\x1a\n this is not really a PNG");
  auto seq = Sequence::open(dir.str());
  REQUIRE(seq.has_value());
  CHECK(seq->read_frame(0).has_value());
  auto bad = seq->read_frame(1);
  REQUIRE_FALSE(bad.has_value());
  CHECK_THAT(bad.error(), Catch::Contains("frames/000001.png"));
  CHECK(seq->read_frame(2).has_value());
}

TEST_CASE("malformed sequence files give file:line errors") {
  TempDir dir;
  write_image_sequence(dir, 3);
  const std::string d = dir.str();
  SECTION("frames.csv with a bad time") {
    dir.write("frames.csv", "frame,t_s,file\n0,0,frames/000000.png\n1,soon,frames/000001.png\n");
    CHECK(open_error(dir) == d + "/frames.csv:3: t_s is not a number ('soon')");
  }
  SECTION("frames.csv with decreasing frames") {
    dir.write("frames.csv", "frame,t_s,file\n1,0,frames/000000.png\n0,0.1,frames/000001.png\n");
    CHECK(open_error(dir) == d + "/frames.csv:3: frame 0 after frame 1 (frames must increase)");
  }
  SECTION("frames.csv with a missing column") {
    dir.write("frames.csv", "frame,t_s,file\r\n0,0,frames/000000.png\r\n\r\n1,0.1\r\n");
    CHECK(open_error(dir) == d + "/frames.csv:4: expected 3 columns, got 2");
  }
  SECTION("frames.csv with a wrong header") {
    dir.write("frames.csv", "frame,time,file\n0,0,frames/000000.png\n");
    CHECK_THAT(open_error(dir), Catch::StartsWith(d + "/frames.csv:1: header must be 'frame,t_s,file'"));
  }
  SECTION("imu.csv with a time that does not increase") {
    dir.write("imu.csv", "t_s,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,9.8\n0.01,0,0,0,0,0,9.8\n0.01,0,0,0,0,0,9.8\n0.02,0,0,0,0,0,9.8\n");
    CHECK_THAT(open_error(dir), Catch::StartsWith(d + "/imu.csv:4: t_s 0.01 is not after the previous sample"));
  }
  SECTION("imu.csv with a non-finite value") {
    dir.write("imu.csv", "t_s,gx,gy,gz,ax,ay,az\n0,0,0,0,0,0,9.8\n0.01,0,inf,0,0,0,9.8\n");
    CHECK(open_error(dir) == d + "/imu.csv:3: gy is not finite ('inf')");
  }
  SECTION("gt.csv with a zero quaternion") {
    dir.write("gt.csv", "frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,1,1,0,0,0\n1,0.1,0,0,1,0,0,0,0\n");
    CHECK(open_error(dir) == d + "/gt.csv:3: zero quaternion (qw,qx,qy,qz all ~0)");
  }
  SECTION("init.csv with two rows") {
    dir.write("init.csv", "frame,t_s,tx,ty,tz,qw,qx,qy,qz\n0,0,0,0,1,1,0,0,0\n1,0.1,0,0,1,1,0,0,0\n");
    CHECK(open_error(dir) == d + "/init.csv: expected exactly one pose row, got 2");
  }
  SECTION("missing init.csv: the sequence opens without a starting pose (detection finds it)") {
    fs::remove(dir.path / "init.csv");
    auto seq = Sequence::open(d);
    REQUIRE(seq);
    CHECK_FALSE(seq->has_init());
    CHECK(seq->init().frame == -1);
  }
  SECTION("missing camera.yaml") {
    fs::remove(dir.path / "camera.yaml");
    CHECK_THAT(open_error(dir), Catch::StartsWith(d + "/camera.yaml: cannot open"));
  }
  SECTION("missing model.cao") {
    fs::remove(dir.path / "model.cao");
    CHECK_THAT(open_error(dir), Catch::Contains(d + "/model.cao"));
  }
}

TEST_CASE("a sequence needs frames from frames.csv or video.mp4") {
  TempDir dir;
  write_image_sequence(dir, 2);
  SECTION("neither") {
    fs::remove(dir.path / "frames.csv");
    CHECK(open_error(dir) == dir.str() + ": no frames (neither frames.csv nor video.mp4)");
  }
  SECTION("empty file column without video.mp4") {
    dir.write("frames.csv", "frame,t_s,file\n0,0,\n1,0.5,\n");
    CHECK_THAT(open_error(dir), Catch::Contains("video.mp4") && Catch::Contains("does not exist"));
  }
  SECTION("images mixed with video frames") {
    dir.write("frames.csv", "frame,t_s,file\n0,0,frames/000000.png\n1,0.5,\n");
    CHECK_THAT(open_error(dir), Catch::Contains("frames.csv: mixes"));
  }
  SECTION("a video OpenCV cannot open") {
    fs::remove(dir.path / "frames.csv");
    dir.write("video.mp4", "not a video at all");
    CHECK(open_error(dir) == dir.str() + "/video.mp4: OpenCV cannot open it (unknown container or codec?)");
  }
  SECTION("not a directory") {
    auto seq = Sequence::open(dir.str() + "/camera.yaml");
    REQUIRE_FALSE(seq.has_value());
    CHECK(seq.error() == dir.str() + "/camera.yaml: not a directory");
  }
}

TEST_CASE("frames.csv with empty file fields takes its times and frames from video.mp4") {
  TempDir dir;
  for (const char* name : {"camera.yaml", "model.cao", "init.csv"}) fs::copy_file(kShared + "/teabox/" + name, dir.path / name);
  fs::create_symlink(kShared + "/teabox/video.mp4", dir.path / "video.mp4");
  dir.write("frames.csv", "frame,t_s,file\n0,10.0,\n1,10.05,\n2,10.1,\n");
  auto seq = Sequence::open(dir.str());
  REQUIRE(seq.has_value());
  REQUIRE(seq->frame_count() == 3);
  CHECK(seq->frames()[1].t_s == 10.05);
  auto image = seq->read_frame(2);
  REQUIRE(image.has_value());
  CHECK(image->cols == 640);

  SECTION("but not more frames than the video has") {
    std::string text = "frame,t_s,file\n";
    for (int i = 0; i < 40; ++i) text += std::to_string(i) + "," + std::to_string(i) + ",\n";
    dir.write("frames.csv", text);
    CHECK_THAT(open_error(dir), Catch::Contains("frames.csv: lists 40 frames but") && Catch::Contains("has 39"));
  }
}

TEST_CASE("write_frames_csv and write_imu_csv refuse what they cannot write") {
  TempDir dir;
  CHECK_FALSE(write_frames_csv(dir.str() + "/f.csv", {{0, 0.0, "a,b.png"}}).has_value());
  CHECK_FALSE(write_imu_csv(dir.str() + "/no/such/dir/imu.csv", {}).has_value());
  REQUIRE(write_imu_csv(dir.str() + "/imu.csv", {}).has_value());
  auto empty = read_imu_csv(dir.str() + "/imu.csv");
  REQUIRE(empty.has_value());
  CHECK(empty->empty());
}

TEST_CASE("frames of another size than the calibration are an error naming the file and both sizes") {
  TempDir dir;
  write_image_sequence(dir, 2);
  // A 320x240 calibration for 640x480 frames tracked with exit 0 and most frames lost.
  REQUIRE(Camera(320, 240, Intrinsics{400, 400, 159.5, 119.5}).save(dir.str() + "/camera.yaml").has_value());
  REQUIRE(cv::imwrite(dir.str() + "/frames/000000.png", cv::Mat(480, 640, CV_8UC3, cv::Scalar(1, 2, 3))));
  auto seq = Sequence::open(dir.str());
  REQUIRE(seq.has_value());
  auto bad = seq->read_frame(0);
  REQUIRE_FALSE(bad.has_value());
  CHECK_THAT(bad.error(), Catch::Contains("frames/000000.png") && Catch::Contains("640x480") &&
                              Catch::Contains("camera.yaml is a calibration for 320x240"));
}

TEST_CASE("video frames of another size than the calibration are an error naming the video and both sizes") {
  TempDir dir;
  for (const char* name : {"model.cao", "init.csv", "video.mp4"}) fs::copy_file(kShared + "/teabox/" + name, dir.path / name);
  REQUIRE(Camera(320, 240, Intrinsics{400, 400, 159.5, 119.5}).save(dir.str() + "/camera.yaml").has_value());
  auto seq = Sequence::open(dir.str());
  REQUIRE(seq.has_value());
  auto bad = seq->read_frame(0);
  REQUIRE_FALSE(bad.has_value());
  CHECK_THAT(bad.error(), Catch::Contains("video.mp4 frame 0") && Catch::Contains("640x480") &&
                              Catch::Contains("calibration for 320x240"));
}

TEST_CASE("the calibration may be camera.yml or camera_info.yaml, and two calibrations in one sequence are an error naming both") {
  TempDir dir;
  write_image_sequence(dir, 2);
  const std::string base = dir.str() + "/";
  for (const char* name : {"camera.yml", "camera_info.yaml"}) {
    std::filesystem::rename(base + "camera.yaml", base + name);
    auto seq = Sequence::open(dir.str());
    INFO(name);
    REQUIRE(seq.has_value());
    CHECK(seq->camera().width_px() == 160);
    std::filesystem::rename(base + name, base + "camera.yaml");
  }
  std::filesystem::copy_file(base + "camera.yaml", base + "camera_info.yaml");
  auto both = Sequence::open(dir.str());
  REQUIRE_FALSE(both.has_value());
  CHECK_THAT(both.error(), Catch::Contains("holds both camera.yaml and camera_info.yaml"));
}
