// Camera::load on the bad camera YAMLs found by fuzzing and by hand: each gives an error that
// names the file and says what is wrong; none throws, none asks for gigabytes.
#include <catch2/catch.hpp>

#include <string>

#include "common/temp_dir.h"
#include "epichead/vision/camera.h"

using epichead::vision::Camera;

namespace {

const std::string kGood =
    "%YAML:1.0\n---\nimage_width: 160\nimage_height: 120\n"
    "camera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n"
    "   data: [ 200., 0., 79.5, 0., 200., 59.5, 0., 0., 1. ]\n"
    "distortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
    "   data: [ 0., 0., 0., 0., 0. ]\n";

// kGood with the first `from` replaced by `to`.
std::string edited(const std::string& from, const std::string& to) {
  std::string s = kGood;
  const auto at = s.find(from);
  REQUIRE(at != std::string::npos);
  return s.replace(at, from.size(), to);
}

std::string load_error(const std::string& text) {
  epichead::testing::TempDir dir("epichead_test_camera_bad");
  const std::string path = dir.write("cam.yaml", text);
  auto cam = Camera::load(path);
  REQUIRE_FALSE(cam.has_value());
  CHECK_THAT(cam.error(), Catch::StartsWith(path + ": "));
  return cam.error();
}

}  // namespace

TEST_CASE("The unedited camera YAML of these tests loads") {
  epichead::testing::TempDir dir("epichead_test_camera_bad");
  auto cam = Camera::load(dir.write("cam.yaml", kGood));
  REQUIRE(cam.has_value());
  CHECK(cam->width_px() == 160);
}

TEST_CASE("An empty key, which makes OpenCV's parser throw std::length_error, is an error with the line") {
  CHECK_THAT(load_error(edited("image_width: 160", "image_width: { :3 }")), Catch::Contains("line 3: empty key"));
  CHECK_THAT(load_error(edited("image_width: 160", "image_width: {a: 1, : 2}")), Catch::Contains("line 3: empty key"));
  CHECK_THAT(load_error(edited("image_height: 120", ": 120")), Catch::Contains("line 4: empty key"));
  CHECK_THAT(load_error(edited("image_height: 120", "\"\": 120")), Catch::Contains("line 4: empty key"));
  // Colons inside quoted text or comments are not keys.
  epichead::testing::TempDir dir("epichead_test_camera_bad");
  auto cam = Camera::load(dir.write("cam.yaml", kGood + "note: \"a: b, : c\"  # x : y\n"));
  CHECK(cam.has_value());
}

TEST_CASE("A typo in rows or cols is an error, not a request for gigabytes") {
  CHECK_THAT(load_error(edited("rows: 3", "rows:`3")), Catch::Contains("camera_matrix.rows must be a whole number"));
  CHECK_THAT(load_error(edited("rows: 3", "rows: 99999")), Catch::Contains("camera_matrix.rows must be 0..16, got 99999"));
  CHECK_THAT(load_error(edited("cols: 3", "cols: -3")), Catch::Contains("camera_matrix.cols must be 0..16"));
  CHECK_THAT(load_error(edited("cols: 5", "cols: 17")), Catch::Contains("distortion_coefficients.cols must be 0..16"));
  CHECK_THAT(load_error(edited("rows: 3", "rows: 3.5")), Catch::Contains("camera_matrix.rows must be a whole number"));
  CHECK_THAT(load_error(edited("   rows: 3\n", "")), Catch::Contains("camera_matrix is not a valid opencv-matrix (no rows)"));
}

TEST_CASE("Matrix data that does not match rows, cols and dt is an error") {
  CHECK_THAT(load_error(edited("0., 0., 1. ]", "0., 0. ]")), Catch::Contains("camera_matrix.data has 8 values, rows x cols is 3x3"));
  CHECK_THAT(load_error(edited("dt: d", "dt: \"3d\"")), Catch::Contains("camera_matrix must have one channel"));
  CHECK_THAT(load_error(edited("   dt: d\n", "")), Catch::Contains("camera_matrix.dt must be"));
  CHECK_THAT(load_error(edited("data: [ 200.,", "data: [ wide,")), Catch::Contains("camera_matrix.data value 1 is not a number"));
  CHECK_THAT(load_error(edited("data: [ 200., 0., 79.5, 0., 200., 59.5, 0., 0., 1. ]", "data: 200.")),
             Catch::Contains("camera_matrix.data must be a list"));
}

TEST_CASE("A file larger than 1 MiB is refused before it is parsed") {
  CHECK_THAT(load_error(kGood + "# " + std::string(1 << 20, 'x') + "\n"), Catch::Contains("larger than any camera calibration"));
}

TEST_CASE("Binary data and text OpenCV cannot parse are errors with the file name") {
  CHECK_THAT(load_error(std::string("%YAML:1.0\n---\na: \0\0", 19)), Catch::Contains("NUL byte"));
  CHECK_THAT(load_error("%YAML:1.0\n---\n? x\n"),
             Catch::Contains("not OpenCV FileStorage YAML (line 3: Complex keys are not supported)"));
  CHECK_THAT(load_error("%YAML:1.0\n---\n- 1\n"), Catch::Contains("cam.yaml: "));
  CHECK_THAT(load_error("%YAML:1.0\n---\ncamera_matrix: { \"\": 2}\n"), Catch::Contains("empty key"));
}

TEST_CASE("A calibration model the reader does not support is an error, never read as another") {
  // A fisheye calibration has k1..k4: five coefficients, or a fisheye_model that is not 0 or 1,
  // is not one that cv::fisheye wrote.
  CHECK_THAT(load_error(edited("image_width: 160", "fisheye_model: 1\nimage_width: 160")),
             Catch::Contains("must have 4 distortion_coefficients (k1..k4), got 5"));
  CHECK_THAT(load_error(edited("image_width: 160", "fisheye_model: 2\nimage_width: 160")),
             Catch::Contains("fisheye_model must be 0 (pinhole) or 1"));
  // ROS's equidistant is the fisheye model: k1..k4, not the five of this file.
  CHECK_THAT(load_error(edited("image_width: 160", "distortion_model: equidistant\nimage_width: 160")),
             Catch::Contains("must have 4 distortion_coefficients (k1..k4), got 5"));
  // ROS's rational_polynomial is k1..k6 with p1 p2: eight, not five.
  CHECK_THAT(load_error(edited("image_width: 160", "distortion_model: rational_polynomial\nimage_width: 160")),
             Catch::Contains("distortion_model rational_polynomial has 8 distortion_coefficients (k1 k2 p1 p2 k3 k4 k5 k6), got 5"));
  CHECK_THAT(load_error(edited("image_width: 160", "distortion_model: fov\nimage_width: 160")),
             Catch::Contains("distortion_model 'fov' is not supported"));
  CHECK_THAT(load_error(edited("image_width: 160", "distortion_model: [ plumb_bob ]\nimage_width: 160")),
             Catch::Contains("distortion_model '(not a name)' is not supported"));
  // Counts OpenCV's calibration never writes, and a NaN among eight.
  CHECK_THAT(load_error(edited("cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]", "cols: 9\n   dt: d\n   data: [ 0., 0., 0., 0., 0., 0., 0., 0., 0. ]")),
             Catch::Contains("distortion_coefficients must have 0, 4, 5, 8, 12 or 14 values (OpenCV's models), got 9"));
  CHECK_THAT(load_error(edited("cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]", "cols: 8\n   dt: d\n   data: [ 0., 0., 0., 0., 0., .nan, 0., 0. ]")),
             Catch::Contains("distortion_coefficients has a non-finite value at (0,5)"));
  CHECK_THAT(load_error(edited("cols: 5\n   dt: d\n   data: [ 0., 0., 0., 0., 0. ]", "cols: 14\n   dt: d\n   data: [ 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0., 0. ]")),
             Catch::Contains("distortion_coefficients.data has 13 values, rows x cols is 1x14"));
  epichead::testing::TempDir dir("epichead_test_camera_bad");
  CHECK(Camera::load(dir.write("a.yaml", edited("image_width: 160", "fisheye_model: 0\nimage_width: 160"))).has_value());
  CHECK(Camera::load(dir.write("b.yaml", edited("image_width: 160", "distortion_model: plumb_bob\nimage_width: 160"))).has_value());
}
