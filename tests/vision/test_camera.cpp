// Camera: OpenCV's distortion model exactly, its Jacobian and inverse, and the YAML reader's
// error paths.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <opencv2/calib3d.hpp>

#include "epichead/vision/camera.h"
#include "common/temp_dir.h"

using epichead::vision::Camera;
using epichead::vision::Distortion;
using epichead::vision::Intrinsics;

namespace {

namespace fs = std::filesystem;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_camera") {}
};

// Wide-angle barrel distortion with tangential terms: the image corner (r ~ 0.8) lies close to
// the radius where the model folds over (~0.89), so the inverse has to work hard there.
Camera strong_camera() {
  return Camera(640, 480, Intrinsics{500.0, 505.0, 322.5, 237.25}, Distortion{-0.35, 0.12, 0.002, -0.001, -0.02});
}

std::string yaml(const std::string& width, const std::string& height, const std::string& k_rows_cols_data,
                 const std::string& d_rows_cols_data) {
  std::string s = "%YAML:1.0\n---\n";
  if (!width.empty()) s += "image_width: " + width + "\n";
  if (!height.empty()) s += "image_height: " + height + "\n";
  if (!k_rows_cols_data.empty()) s += "camera_matrix: " + k_rows_cols_data + "\n";
  if (!d_rows_cols_data.empty()) s += "distortion_coefficients: " + d_rows_cols_data + "\n";
  return s;
}

std::string matrix(int rows, int cols, const std::string& data) {
  return "!!opencv-matrix\n   rows: " + std::to_string(rows) + "\n   cols: " + std::to_string(cols) +
         "\n   dt: d\n   data: [ " + data + " ]";
}

const std::string kGoodK = matrix(3, 3, "500., 0., 320., 0., 510., 240., 0., 0., 1.");
const std::string kGoodD = matrix(1, 5, "-0.1, 0.01, 0.001, 0.002, 0.0005");

std::string load_error(const TempDir& dir, const std::string& text) {
  const std::string path = dir.write("camera.yaml", text);
  auto cam = Camera::load(path);
  REQUIRE_FALSE(cam.has_value());
  return cam.error();
}

}  // namespace

TEST_CASE("pixel_to_normalized inverts normalized_to_pixel over the whole image under strong distortion") {
  const Camera cam = strong_camera();
  REQUIRE(cam.has_distortion());
  double worst_px = 0;
  for (double v = -0.5; v <= 479.5; v += 4.0) {
    for (double u = -0.5; u <= 639.5; u += 4.0) {
      const Eigen::Vector2d px(u, v);
      const Eigen::Vector2d back = cam.normalized_to_pixel(cam.pixel_to_normalized(px));
      worst_px = std::max(worst_px, (back - px).norm());
    }
  }
  CHECK(worst_px < 1e-6);
}

TEST_CASE("normalized_to_pixel then pixel_to_normalized returns the same normalised point") {
  const Camera cam = strong_camera();
  double worst = 0;
  for (double y = -0.45; y <= 0.45; y += 0.03)
    for (double x = -0.6; x <= 0.6; x += 0.03) {
      const Eigen::Vector2d xn(x, y);
      worst = std::max(worst, (cam.pixel_to_normalized(cam.normalized_to_pixel(xn)) - xn).norm());
    }
  CHECK(worst < 1e-10);
}

TEST_CASE("project agrees with cv::projectPoints") {
  const Camera cam = strong_camera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-0.5, 0.5), z(0.8, 3.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) {
    const double zz = z(rng);
    points.emplace_back(xy(rng) * zz, xy(rng) * zz, zz);
  }
  const auto& k = cam.intrinsics();
  const cv::Mat K = (cv::Mat_<double>(3, 3) << k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  const auto& d = cam.distortion();
  const cv::Mat D = (cv::Mat_<double>(1, 5) << d[0], d[1], d[2], d[3], d[4]);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, expected);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d px = cam.project({points[i].x, points[i].y, points[i].z});
    worst = std::max(worst, (px - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
  }
  CHECK(worst < 1e-9);
}

TEST_CASE("pixel_to_normalized agrees with a tightly converged cv::undistortPoints") {
  const Camera cam(640, 480, Intrinsics{600, 600, 320, 240}, Distortion{-0.2, 0.05, 0.001, -0.001, 0.0});
  const cv::Mat K = (cv::Mat_<double>(3, 3) << 600, 0, 320, 0, 600, 240, 0, 0, 1);
  const cv::Mat D = (cv::Mat_<double>(1, 5) << -0.2, 0.05, 0.001, -0.001, 0.0);
  std::vector<cv::Point2d> px{{0, 0}, {639, 479}, {100, 400}, {320, 240}, {600, 20}}, out;
  cv::undistortPoints(px, out, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 1000, 1e-15));
  for (std::size_t i = 0; i < px.size(); ++i) {
    const Eigen::Vector2d xn = cam.pixel_to_normalized({px[i].x, px[i].y});
    CHECK(xn.x() == Approx(out[i].x).margin(1e-8));
    CHECK(xn.y() == Approx(out[i].y).margin(1e-8));
  }
}

TEST_CASE("pixel_to_normalized stays finite far outside the image, where the model folds over") {
  for (const Camera& cam : {strong_camera(), Camera(640, 480, Intrinsics{500, 500, 320, 240}, Distortion{0.4, 0.3, 0, 0, 0.1})}) {
    for (const Eigen::Vector2d& px : {Eigen::Vector2d(1e6, -1e6), Eigen::Vector2d(-5000, 3000), Eigen::Vector2d(2000, 240),
                                     Eigen::Vector2d(1e12, 1e12)}) {
      const Eigen::Vector2d xn = cam.pixel_to_normalized(px);
      CHECK(xn.allFinite());
    }
  }
}

TEST_CASE("normalized_to_pixel_jacobian matches finite differences") {
  const Camera cam = strong_camera();
  const double h = 1e-6;
  for (const Eigen::Vector2d& xn : {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.6, 0.45),
                                   Eigen::Vector2d(0.05, 0.4)}) {
    const Eigen::Matrix2d J = cam.normalized_to_pixel_jacobian(xn);
    Eigen::Matrix2d numeric;
    for (int c = 0; c < 2; ++c) {
      Eigen::Vector2d d = Eigen::Vector2d::Zero();
      d[c] = h;
      numeric.col(c) = (cam.normalized_to_pixel(xn + d) - cam.normalized_to_pixel(xn - d)) / (2 * h);
    }
    CHECK((J - numeric).norm() < 1e-4);  // pixels per unit: J is ~500
  }
  const Camera plain(640, 480, Intrinsics{500, 510, 320, 240});
  const Eigen::Matrix2d J = plain.normalized_to_pixel_jacobian({0.2, 0.1});
  CHECK(J(0, 0) == 500);
  CHECK(J(1, 1) == 510);
  CHECK(J(0, 1) == 0);
}

TEST_CASE("project returns NaN for points at or behind the camera") {
  const Camera cam = strong_camera();
  CHECK_FALSE(cam.project({0.1, 0.1, 0}).allFinite());
  CHECK_FALSE(cam.project({0.1, 0.1, -1}).allFinite());
  const Eigen::Vector3d ray = cam.unproject(cam.project({0.2, -0.1, 2.0}));
  CHECK(ray.z() == 1);
  CHECK(ray.x() == Approx(0.1).margin(1e-12));
  CHECK(ray.y() == Approx(-0.05).margin(1e-12));
}

TEST_CASE("in_image uses pixel centres 0..width-1 and the margin") {
  const Camera cam(640, 480, Intrinsics{500, 500, 320, 240});
  CHECK(cam.in_image({0, 0}));
  CHECK(cam.in_image({639, 479}));
  CHECK_FALSE(cam.in_image({639.5, 10}));
  CHECK_FALSE(cam.in_image({-0.1, 10}));
  CHECK_FALSE(cam.in_image({5, 10}, 10));
  CHECK(cam.in_image({10, 10}, 10));
  CHECK_FALSE(cam.in_image({std::nan(""), 10}));
}

TEST_CASE("the constructor rejects non-positive sizes and focal lengths") {
  CHECK_THROWS_AS(Camera(0, 480, Intrinsics{500, 500, 320, 240}), std::invalid_argument);
  CHECK_THROWS_AS(Camera(640, -1, Intrinsics{500, 500, 320, 240}), std::invalid_argument);
  CHECK_THROWS_AS(Camera(640, 480, Intrinsics{0, 500, 320, 240}), std::invalid_argument);
  CHECK_THROWS_AS(Camera(640, 480, Intrinsics{500, -2, 320, 240}), std::invalid_argument);
}

TEST_CASE("save then load gives back the same camera exactly") {
  TempDir dir;
  const Camera cam = strong_camera();
  const std::string path = (dir.path / "cam.yaml").string();
  REQUIRE(cam.save(path).has_value());
  auto back = Camera::load(path);
  REQUIRE(back.has_value());
  CHECK(back->width_px() == 640);
  CHECK(back->height_px() == 480);
  CHECK(back->intrinsics().fx_px == cam.intrinsics().fx_px);
  CHECK(back->intrinsics().fy_px == cam.intrinsics().fy_px);
  CHECK(back->intrinsics().cx_px == cam.intrinsics().cx_px);
  CHECK(back->intrinsics().cy_px == cam.intrinsics().cy_px);
  CHECK(back->distortion() == cam.distortion());
  CHECK(back->K() == cam.K());
}

TEST_CASE("save reports a directory that does not exist") {
  const Camera cam = strong_camera();
  auto r = cam.save("/nonexistent-dir-epichead/cam.yaml");
  REQUIRE_FALSE(r.has_value());
  CHECK_THAT(r.error(), Catch::Contains("/nonexistent-dir-epichead/cam.yaml"));
}

TEST_CASE("the teabox camera.yaml loads") {
  auto cam = Camera::load(std::string(EPICHEAD_SHARED_DATA) + "/teabox/camera.yaml");
  REQUIRE(cam.has_value());
  CHECK(cam->width_px() == 640);
  CHECK(cam->height_px() == 480);
  CHECK(cam->intrinsics().fx_px == Approx(839.2147));
  CHECK(cam->intrinsics().cy_px == Approx(243.69727));
  CHECK_FALSE(cam->has_distortion());
}

TEST_CASE("distortion_coefficients with 4 values, none, or a column are accepted") {
  TempDir dir;
  SECTION("1x4 means k3 = 0") {
    auto cam = Camera::load(dir.write("c.yaml", yaml("640", "480", kGoodK, matrix(1, 4, "-0.1, 0.01, 0.001, 0.002"))));
    REQUIRE(cam.has_value());
    CHECK(cam->distortion() == Distortion{-0.1, 0.01, 0.001, 0.002, 0});
  }
  SECTION("5x1") {
    auto cam = Camera::load(dir.write("c.yaml", yaml("640", "480", kGoodK, matrix(5, 1, "-0.1, 0.01, 0.001, 0.002, 0.5"))));
    REQUIRE(cam.has_value());
    CHECK(cam->distortion()[4] == 0.5);
  }
  SECTION("empty") {
    auto cam = Camera::load(dir.write("c.yaml", yaml("640", "480", kGoodK, matrix(0, 0, ""))));
    REQUIRE(cam.has_value());
    CHECK_FALSE(cam->has_distortion());
  }
}

TEST_CASE("camera YAML errors name the file and the field") {
  TempDir dir;
  SECTION("missing file") {
    auto cam = Camera::load((dir.path / "nope.yaml").string());
    REQUIRE_FALSE(cam.has_value());
    CHECK_THAT(cam.error(), Catch::Contains("nope.yaml") && Catch::Contains("cannot open"));
  }
  SECTION("not YAML") {
    CHECK_THAT(load_error(dir, "this { is [ not : yaml ]]] :\n\t- -\n"), Catch::Contains("camera.yaml: "));
    CHECK_THAT(load_error(dir, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16)), Catch::Contains("camera.yaml: "));
    CHECK_THAT(load_error(dir, ""), Catch::Contains("camera.yaml: "));
  }
  SECTION("missing fields") {
    CHECK_THAT(load_error(dir, yaml("640", "480", "", kGoodD)), Catch::Contains("camera.yaml: missing field 'camera_matrix'"));
    CHECK_THAT(load_error(dir, yaml("", "480", kGoodK, kGoodD)), Catch::Contains("camera.yaml: missing field 'image_width'"));
    CHECK_THAT(load_error(dir, yaml("640", "", kGoodK, kGoodD)), Catch::Contains("camera.yaml: missing field 'image_height'"));
    CHECK_THAT(load_error(dir, yaml("640", "480", kGoodK, "")),
               Catch::Contains("camera.yaml: missing field 'distortion_coefficients'"));
  }
  SECTION("camera_matrix shape and content") {
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 2, "1, 0, 0, 1, 0, 0"), kGoodD)),
               Catch::Contains("camera.yaml: camera_matrix must be 3x3, got 3x2"));
    CHECK_THAT(load_error(dir, yaml("640", "480", "42", kGoodD)), Catch::Contains("camera.yaml: camera_matrix must be"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "0., 0., 320., 0., 510., 240., 0., 0., 1."), kGoodD)),
               Catch::Contains("camera.yaml: fx must be positive"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "500., 0., 320., 0., -510., 240., 0., 0., 1."), kGoodD)),
               Catch::Contains("camera.yaml: fy must be positive"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "500., 0., .nan, 0., 510., 240., 0., 0., 1."), kGoodD)),
               Catch::Contains("camera.yaml: camera_matrix has a non-finite value"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "500., 0., .inf, 0., 510., 240., 0., 0., 1."), kGoodD)),
               Catch::Contains("camera.yaml: camera_matrix has a non-finite value"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "500., 3., 320., 0., 510., 240., 0., 0., 1."), kGoodD)),
               Catch::Contains("skew"));
    CHECK_THAT(load_error(dir, yaml("640", "480", matrix(3, 3, "500., 0., 320., 0., 510., 240., 0., 0., 2."), kGoodD)),
               Catch::Contains("camera.yaml: camera_matrix must have the form"));
  }
  SECTION("image sizes") {
    CHECK_THAT(load_error(dir, yaml("0", "480", kGoodK, kGoodD)), Catch::Contains("camera.yaml: image_width must be positive"));
    CHECK_THAT(load_error(dir, yaml("640", "-480", kGoodK, kGoodD)), Catch::Contains("camera.yaml: image_height must be positive"));
    CHECK_THAT(load_error(dir, yaml("640.5", "480", kGoodK, kGoodD)), Catch::Contains("camera.yaml: image_width must be a whole number"));
    CHECK_THAT(load_error(dir, yaml("wide", "480", kGoodK, kGoodD)), Catch::Contains("camera.yaml: image_width must be a number"));
  }
  SECTION("distortion models we do not have") {
    CHECK_THAT(load_error(dir, yaml("640", "480", kGoodK, matrix(1, 9, "0.1, 0, 0, 0, 0, 0.2, 0, 0, 0"))),
               Catch::Contains("camera.yaml: distortion_coefficients must have 0, 4, 5, 8, 12 or 14 values (OpenCV's models), got 9"));
    CHECK_THAT(load_error(dir, yaml("640", "480", kGoodK, matrix(1, 3, "0.1, 0, 0"))),
               Catch::Contains("camera.yaml: distortion_coefficients must have 0, 4, 5, 8, 12 or 14 values (OpenCV's models), got 3"));
    CHECK_THAT(load_error(dir, yaml("640", "480", kGoodK, matrix(2, 3, "0.1, 0, 0, 0, 0, 0"))),
               Catch::Contains("camera.yaml: distortion_coefficients must be a row or column vector, got 2x3"));
    CHECK_THAT(load_error(dir, yaml("640", "480", kGoodK, matrix(1, 5, "0.1, 0, .nan, 0, 0"))),
               Catch::Contains("camera.yaml: distortion_coefficients has a non-finite value"));
  }
}

namespace {

// A wide fisheye lens of the kind cv::fisheye::calibrate is used for (about 180 deg across the
// diagonal of a 640x480 image).
Camera fisheye_camera() {
  return Camera(640, 480, Intrinsics{210.0, 212.0, 318.5, 241.25}, Distortion{0.08, -0.03, 0.01, -0.002, 0.0},
                epichead::vision::LensModel::Fisheye);
}

}  // namespace

TEST_CASE("the fisheye model projects as cv::fisheye::projectPoints, out to rays 85 deg off the axis") {
  const Camera cam = fisheye_camera();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> off_axis(0.0, 85.0 * M_PI / 180.0), around(-M_PI, M_PI), dist(0.3, 4.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 500; ++i) {
    const double a = off_axis(rng), b = around(rng), r = dist(rng);
    points.emplace_back(r * std::sin(a) * std::cos(b), r * std::sin(a) * std::sin(b), r * std::cos(a));
  }
  points.emplace_back(0.0, 0.0, 1.0);  // on the axis: the model's 0/0
  const auto& k = cam.intrinsics();
  const cv::Matx33d K(k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  const auto& d = cam.distortion();
  const cv::Vec4d D(d[0], d[1], d[2], d[3]);
  std::vector<cv::Point2d> expected;
  cv::fisheye::projectPoints(points, expected, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  double worst = 0, inverse = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p(points[i].x, points[i].y, points[i].z);
    const Eigen::Vector2d px = cam.project(p);
    worst = std::max(worst, (px - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
    inverse = std::max(inverse, (cam.unproject(px) - p / p.z()).norm() / (p / p.z()).norm() * (p.z() > 0));
  }
  CHECK(worst < 1e-6);  // the issue asks for 0.01 px
  CHECK(inverse < 1e-9);
}

TEST_CASE("the fisheye model unprojects as cv::fisheye::undistortPoints, out to rays 80 deg off the axis") {
  const Camera cam = fisheye_camera();
  const auto& k = cam.intrinsics();
  const cv::Matx33d K(k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  const auto& d = cam.distortion();
  const cv::Vec4d D(d[0], d[1], d[2], d[3]);
  // Pixels where the lens images rays up to 80 deg off its axis. Beyond the angle where the
  // distortion polynomial turns back there is no inverse, and both disagree with any truth.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> off_axis(0.0, 80.0 * M_PI / 180.0), around(-M_PI, M_PI);
  std::vector<cv::Point2d> pixels;
  for (int i = 0; i < 500; ++i) {
    const double a = off_axis(rng), b = around(rng);
    const Eigen::Vector2d px = cam.project(Eigen::Vector3d(std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)));
    pixels.emplace_back(px.x(), px.y());
  }
  std::vector<cv::Point2d> expected;
  cv::fisheye::undistortPoints(pixels, expected, K, D, cv::noArray(), cv::noArray(),
                               cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-14));
  double worst = 0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    const Eigen::Vector3d ray = cam.unproject(Eigen::Vector2d(pixels[i].x, pixels[i].y));
    const Eigen::Vector2d xn = ray.head<2>() / ray.z();
    worst = std::max(worst, (xn - Eigen::Vector2d(expected[i].x, expected[i].y)).norm() / std::max(1.0, xn.norm()));
  }
  CHECK(worst < 1e-6);
}

TEST_CASE("the fisheye model's Jacobian matches finite differences, on the axis too") {
  const Camera cam = fisheye_camera();
  for (const Eigen::Vector2d& xn : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1e-9, -2e-9), Eigen::Vector2d(0.3, -0.2),
                                   Eigen::Vector2d(-2.5, 4.0)}) {
    const Eigen::Matrix2d J = cam.normalized_to_pixel_jacobian(xn);
    constexpr double h = 1e-6;
    for (int c = 0; c < 2; ++c) {
      const Eigen::Vector2d e = Eigen::Vector2d::Unit(c) * h;
      const Eigen::Vector2d numeric = (cam.normalized_to_pixel(xn + e) - cam.normalized_to_pixel(xn - e)) / (2 * h);
      INFO("at " << xn.transpose() << " column " << c);
      CHECK((J.col(c) - numeric).norm() < 1e-4 * std::max(1.0, numeric.norm()));
    }
  }
}

TEST_CASE("a calibration cv::fisheye wrote loads as the fisheye model and saves back the same") {
  TempDir dir;
  const Camera written = fisheye_camera();
  const std::string path = (dir.path / "fisheye.yaml").string();
  {
    // As OpenCV's own calibration samples write a cv::fisheye result.
    cv::FileStorage fs(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
    const auto& k = written.intrinsics();
    const auto& d = written.distortion();
    fs << "image_width" << 640 << "image_height" << 480 << "fisheye_model" << 1;
    fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
    fs << "distortion_coefficients" << (cv::Mat_<double>(4, 1) << d[0], d[1], d[2], d[3]);
  }
  auto cam = Camera::load(path);
  REQUIRE(cam);
  CHECK(cam->lens() == epichead::vision::LensModel::Fisheye);
  CHECK(cam->has_distortion());
  const Eigen::Vector3d p(0.9, -0.4, 0.6);
  CHECK((cam->project(p) - written.project(p)).norm() == 0.0);

  const std::string again = (dir.path / "again.yaml").string();
  REQUIRE(cam->save(again));
  auto reread = Camera::load(again);
  REQUIRE(reread);
  CHECK(reread->lens() == epichead::vision::LensModel::Fisheye);
  CHECK(reread->distortion() == written.distortion());
  CHECK((reread->project(p) - written.project(p)).norm() == 0.0);
}

namespace {

// Chessboard corners (9 x 6, 25 mm) seen from `views` poses around the board, as a calibration
// session collects them: rotation vectors and translations of the board in the camera.
struct Board {
  std::vector<std::vector<cv::Vec3d>> object;
  std::vector<cv::Vec3d> rvecs, tvecs;
};
Board board_views(int views) {
  Board b;
  std::vector<cv::Vec3d> corners;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) corners.emplace_back((c - 4) * 0.025, (r - 2.5) * 0.025, 0.0);
  for (int v = 0; v < views; ++v) {
    const double a = 2 * M_PI * v / views;
    b.object.push_back(corners);
    b.rvecs.emplace_back(0.5 * std::cos(a), 0.5 * std::sin(a), 0.2 * std::sin(2 * a));
    b.tvecs.emplace_back(0.08 * std::cos(a), 0.06 * std::sin(a), 0.22 + 0.03 * (v % 3));
  }
  return b;
}

}  // namespace

TEST_CASE("a calibration cv::fisheye::calibrate made, saved as OpenCV saves it, projects within 0.01 px of cv::fisheye::projectPoints") {
  // The lens: fisheye_camera(). Its images of the board are what cv::fisheye::calibrate gets.
  const Camera lens = fisheye_camera();
  const Board board = board_views(12);
  const cv::Matx33d K_true(lens.intrinsics().fx_px, 0, lens.intrinsics().cx_px, 0, lens.intrinsics().fy_px,
                           lens.intrinsics().cy_px, 0, 0, 1);
  const cv::Vec4d D_true(lens.distortion()[0], lens.distortion()[1], lens.distortion()[2], lens.distortion()[3]);
  std::vector<std::vector<cv::Vec2d>> image(board.object.size());
  for (std::size_t v = 0; v < board.object.size(); ++v)
    cv::fisheye::projectPoints(board.object[v], image[v], board.rvecs[v], board.tvecs[v], K_true, D_true);
  cv::Matx33d K;
  cv::Vec4d D;
  std::vector<cv::Vec3d> rvecs, tvecs;
  const double rms = cv::fisheye::calibrate(board.object, image, cv::Size(640, 480), K, D, rvecs, tvecs,
                                            cv::fisheye::CALIB_RECOMPUTE_EXTRINSIC | cv::fisheye::CALIB_FIX_SKEW,
                                            cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  INFO("calibration rms " << rms << " px, K " << cv::Mat(K) << ", D " << cv::Mat(D));
  REQUIRE(rms < 0.1);

  TempDir dir;
  const std::string path = (dir.path / "fisheye_calibration.yaml").string();
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);  // the format from the extension, as the samples do
    fs << "image_width" << 640 << "image_height" << 480 << "fisheye_model" << 1;
    fs << "camera_matrix" << cv::Mat(K) << "distortion_coefficients" << cv::Mat(D);
    fs << "avg_reprojection_error" << rms;
  }
  auto cam = Camera::load(path);
  REQUIRE(cam);
  CHECK(cam->lens() == epichead::vision::LensModel::Fisheye);
  std::vector<cv::Point3d> points;
  for (double a = 0; a < 85; a += 5)
    for (double b = -180; b < 180; b += 20)
      points.emplace_back(std::sin(a * M_PI / 180) * std::cos(b * M_PI / 180), std::sin(a * M_PI / 180) * std::sin(b * M_PI / 180),
                          std::cos(a * M_PI / 180));
  std::vector<cv::Point2d> expected;
  cv::fisheye::projectPoints(points, expected, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, (cam->project({points[i].x, points[i].y, points[i].z}) -
                             Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
  CHECK(worst < 0.01);  // the bar; the model is the same formula, so it is far inside it
  CHECK(worst < 1e-6);
}

namespace {

// What ROS's camera_calibration writes (camera_info YAML): plain YAML, matrices as {rows, cols, data}.
std::string ros_camera_info(const std::string& model, const std::string& coefficients, int n) {
  return "image_width: 640\nimage_height: 480\ncamera_name: head_camera\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
         "  data: [500.0, 0.0, 320.5, 0.0, 505.0, 240.25, 0.0, 0.0, 1.0]\ndistortion_model: " + model +
         "\ndistortion_coefficients:\n  rows: 1\n  cols: " + std::to_string(n) + "\n  data: [" + coefficients +
         "]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
         "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [500.0, 0.0, 320.5, 0.0, 0.0, 505.0, 240.25, 0.0, 0.0, 0.0, 1.0, 0.0]\n";
}

}  // namespace

TEST_CASE("a ROS camera_info YAML loads: plumb_bob as the pinhole model, equidistant as the fisheye, and a model not known is an error") {
  TempDir dir;
  auto pinhole = Camera::load(dir.write("camera_info.yaml", ros_camera_info("plumb_bob", "-0.1, 0.01, 0.001, 0.002, 0.0005", 5)));
  REQUIRE(pinhole);
  CHECK(pinhole->lens() == epichead::vision::LensModel::Pinhole);
  CHECK(pinhole->width_px() == 640);
  CHECK(pinhole->intrinsics().fy_px == 505.0);
  CHECK(pinhole->intrinsics().cx_px == 320.5);
  CHECK(pinhole->distortion() == Distortion{-0.1, 0.01, 0.001, 0.002, 0.0005});

  auto fisheye = Camera::load(dir.write("fisheye.yaml", ros_camera_info("equidistant", "0.08, -0.03, 0.01, -0.002", 4)));
  REQUIRE(fisheye);
  CHECK(fisheye->lens() == epichead::vision::LensModel::Fisheye);
  CHECK(fisheye->distortion() == Distortion{0.08, -0.03, 0.01, -0.002, 0.0});

  // A model ROS drivers write that this reader does not have (the FOV model of some SLAM
  // calibrations): an error, not plumb_bob's polynomial with the wrong meaning.
  auto fov = Camera::load(dir.write("fov.yaml", ros_camera_info("fov", "0.93", 1)));
  REQUIRE_FALSE(fov);
  CHECK_THAT(fov.error(), Catch::Contains("fov.yaml: distortion_model 'fov' is not supported"));
  auto five = Camera::load(dir.write("five.yaml", ros_camera_info("equidistant", "0.08, -0.03, 0.01, -0.002, 0", 5)));
  REQUIRE_FALSE(five);
  CHECK_THAT(five.error(), Catch::Contains("must have 4 distortion_coefficients (k1..k4), got 5"));
}
