// Camera: OpenCV's rational (8 coefficients), thin-prism (12) and tilted-sensor (14) models
// exactly as cv::projectPoints, their Jacobian and inverse, and the calibration files that hold
// them (OpenCV's FileStorage and ROS's rational_polynomial camera_info).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "common/temp_dir.h"
#include "epichead/vision/camera.h"

using epichead::vision::Camera;
using epichead::vision::Distortion;
using epichead::vision::Intrinsics;

namespace {

// A wide-angle lens calibrated with CALIB_RATIONAL_MODEL: large k1..k6 that mostly cancel, as
// such calibrations have them.
constexpr Distortion kRational{0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082};
// The same with CALIB_THIN_PRISM_MODEL's s1..s4 and CALIB_TILTED_MODEL's taux, tauy (radians).
constexpr Distortion kThinPrism{0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082, 0.0021, -0.0004, -0.0015, 0.0003};
constexpr Distortion kTilted{0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082, 0.0021, -0.0004, -0.0015, 0.0003,
                             0.012, -0.021};

const Intrinsics kK{520.0, 523.5, 318.25, 243.5};

Camera camera(const Distortion& d) { return Camera(640, 480, kK, d); }

struct Model {
  const char* name;
  Distortion d;
  int n;  // the distCoeffs length OpenCV is given
};
const Model kModels[] = {{"rational (8)", kRational, 8}, {"thin prism (12)", kThinPrism, 12}, {"tilted (14)", kTilted, 14}};

cv::Mat opencv_K() { return (cv::Mat_<double>(3, 3) << kK.fx_px, 0, kK.cx_px, 0, kK.fy_px, kK.cy_px, 0, 0, 1); }
cv::Mat opencv_D(const Distortion& d, int n) {
  cv::Mat D(1, n, CV_64F);
  for (int i = 0; i < n; ++i) D.at<double>(i) = d[static_cast<std::size_t>(i)];
  return D;
}

// Points in front of the camera whose images cover the 640x480 image and a little beyond.
std::vector<cv::Point3d> points_over_image() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> x(-0.72, 0.72), y(-0.55, 0.55), z(0.3, 5.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 500; ++i) {
    const double zz = z(rng);
    points.emplace_back(x(rng) * zz, y(rng) * zz, zz);
  }
  points.emplace_back(0.0, 0.0, 1.0);
  return points;
}

}  // namespace

TEST_CASE("the rational, thin-prism and tilted models project as cv::projectPoints") {
  const std::vector<cv::Point3d> points = points_over_image();
  for (const Model& m : kModels) {
    INFO(m.name);
    const Camera cam = camera(m.d);
    REQUIRE(cam.has_distortion());
    std::vector<cv::Point2d> expected;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), opencv_K(), opencv_D(m.d, m.n), expected);
    double worst = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d px = cam.project({points[i].x, points[i].y, points[i].z});
      worst = std::max(worst, (px - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
    }
    CHECK(worst < 1e-9);
  }
}

TEST_CASE("the 5-coefficient model gives the same pixels through 14 coefficients as cv::projectPoints with 5") {
  const Distortion d{-0.28, 0.09, 0.001, -0.0007, -0.012};
  const std::vector<cv::Point3d> points = points_over_image();
  std::vector<cv::Point2d> five, fourteen;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), opencv_K(), opencv_D(d, 5), five);
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), opencv_K(), opencv_D(d, 14), fourteen);
  const Camera cam = camera(d);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d px = cam.project({points[i].x, points[i].y, points[i].z});
    worst = std::max(worst, (px - Eigen::Vector2d(five[i].x, five[i].y)).norm());
    worst = std::max(worst, (px - Eigen::Vector2d(fourteen[i].x, fourteen[i].y)).norm());
  }
  CHECK(worst < 1e-9);
}

TEST_CASE("unproject inverts project for the rational, thin-prism and tilted models over the whole image") {
  for (const Model& m : kModels) {
    INFO(m.name);
    const Camera cam = camera(m.d);
    double worst_px = 0, worst_ray = 0;
    for (double v = -0.5; v <= 479.5; v += 8.0) {
      for (double u = -0.5; u <= 639.5; u += 8.0) {
        const Eigen::Vector2d px(u, v);
        const Eigen::Vector3d ray = cam.unproject(px);
        worst_px = std::max(worst_px, (cam.project(ray) - px).norm());
      }
    }
    for (double y = -0.5; y <= 0.5; y += 0.05)
      for (double x = -0.65; x <= 0.65; x += 0.05) {
        const Eigen::Vector2d xn(x, y);
        worst_ray = std::max(worst_ray, (cam.pixel_to_normalized(cam.normalized_to_pixel(xn)) - xn).norm());
      }
    CHECK(worst_px < 1e-9);
    CHECK(worst_ray < 1e-11);
  }
}

TEST_CASE("unproject agrees with a tightly converged cv::undistortPoints for the rational, thin-prism and tilted models") {
  const std::vector<cv::Point2d> px{{0, 0}, {639, 479}, {100, 400}, {318.25, 243.5}, {600, 20}, {320, 5}};
  for (const Model& m : kModels) {
    INFO(m.name);
    const Camera cam = camera(m.d);
    std::vector<cv::Point2d> out;
    cv::undistortPoints(px, out, opencv_K(), opencv_D(m.d, m.n), cv::noArray(), cv::noArray(),
                        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 5000, 1e-15));
    for (std::size_t i = 0; i < px.size(); ++i) {
      const Eigen::Vector2d xn = cam.pixel_to_normalized({px[i].x, px[i].y});
      CHECK(xn.x() == Approx(out[i].x).margin(1e-8));
      CHECK(xn.y() == Approx(out[i].y).margin(1e-8));
    }
  }
}

TEST_CASE("the Jacobian of the rational, thin-prism and tilted models matches finite differences") {
  for (const Model& m : kModels) {
    INFO(m.name);
    const Camera cam = camera(m.d);
    for (const Eigen::Vector2d& xn : {Eigen::Vector2d(0, 0), Eigen::Vector2d(0.3, -0.2), Eigen::Vector2d(-0.6, 0.45),
                                     Eigen::Vector2d(0.05, 0.4), Eigen::Vector2d(0.7, 0.5)}) {
      const Eigen::Matrix2d J = cam.normalized_to_pixel_jacobian(xn);
      constexpr double h = 1e-6;
      Eigen::Matrix2d numeric;
      for (int c = 0; c < 2; ++c) {
        const Eigen::Vector2d e = Eigen::Vector2d::Unit(c) * h;
        numeric.col(c) = (cam.normalized_to_pixel(xn + e) - cam.normalized_to_pixel(xn - e)) / (2 * h);
      }
      INFO("at " << xn.transpose() << "\nJ\n" << J << "\nnumeric\n" << numeric);
      CHECK((J - numeric).norm() < 1e-4);  // pixels per unit: J is ~500
    }
  }
}

namespace {

// distortion_coefficients as OpenCV's calibration sample writes them: the cv::Mat that
// calibrateCamera returned (a column), beside the camera matrix, with FileStorage.
std::string write_opencv(const epichead::testing::TempDir& dir, const std::string& name, const cv::Mat& D) {
  const std::string path = (dir.path / name).string();
  cv::FileStorage fs(path, cv::FileStorage::WRITE | cv::FileStorage::FORMAT_YAML);
  fs << "calibration_time" << "Fri 04 Dec 2026" << "image_width" << 640 << "image_height" << 480;
  fs << "flags" << (cv::CALIB_RATIONAL_MODEL | cv::CALIB_THIN_PRISM_MODEL | cv::CALIB_TILTED_MODEL);
  fs << "camera_matrix" << opencv_K() << "distortion_coefficients" << D;
  fs << "avg_reprojection_error" << 0.21;
  return path;
}

// How many distortion_coefficients a file holds, as OpenCV reads it.
int coefficients_in(const std::string& path) {
  cv::FileStorage fs(path, cv::FileStorage::READ);
  cv::Mat D;
  fs["distortion_coefficients"] >> D;
  return static_cast<int>(D.total());
}

}  // namespace

TEST_CASE("calibrations OpenCV wrote with 8, 12 and 14 coefficients load, project as OpenCV, and save back with as many") {
  epichead::testing::TempDir dir("epichead_test_camera_rational");
  const std::vector<cv::Point3d> points = points_over_image();
  for (const Model& m : kModels) {
    INFO(m.name);
    for (const bool column : {true, false}) {
      const cv::Mat D = column ? cv::Mat(opencv_D(m.d, m.n).t()) : opencv_D(m.d, m.n);
      auto cam = Camera::load(write_opencv(dir, "cal.yaml", D));
      REQUIRE(cam);
      CHECK(cam->distortion() == m.d);
      std::vector<cv::Point2d> expected;
      cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), opencv_K(), D, expected);
      double worst = 0;
      for (std::size_t i = 0; i < points.size(); ++i)
        worst = std::max(worst, (cam->project({points[i].x, points[i].y, points[i].z}) -
                                 Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
      CHECK(worst < 1e-9);

      const std::string again = (dir.path / "again.yaml").string();
      REQUIRE(cam->save(again));
      CHECK(coefficients_in(again) == m.n);
      auto reread = Camera::load(again);
      REQUIRE(reread);
      CHECK(reread->distortion() == m.d);
    }
  }
}

TEST_CASE("a calibration cv::calibrateCamera made with the rational, thin-prism and tilted models loads and projects as OpenCV") {
  // A chessboard session (9 x 6, 25 mm, 14 views) through the 14-coefficient lens.
  std::vector<cv::Point3f> corners;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) corners.emplace_back(static_cast<float>((c - 4) * 0.025), static_cast<float>((r - 2.5) * 0.025), 0.f);
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (int v = 0; v < 14; ++v) {
    const double a = 2 * M_PI * v / 14;
    std::vector<cv::Point2f> seen;
    cv::projectPoints(corners, cv::Vec3d(0.5 * std::cos(a), 0.5 * std::sin(a), 0.2 * std::sin(2 * a)),
                      cv::Vec3d(0.1 * std::cos(a), 0.07 * std::sin(a), 0.25 + 0.04 * (v % 3)), opencv_K(),
                      opencv_D(kTilted, 14), seen);
    object.push_back(corners);
    image.push_back(seen);
  }
  cv::Mat K, D;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(object, image, cv::Size(640, 480), K, D, rvecs, tvecs,
                                         cv::CALIB_RATIONAL_MODEL | cv::CALIB_THIN_PRISM_MODEL | cv::CALIB_TILTED_MODEL);
  INFO("rms " << rms << " px, D " << D);
  REQUIRE(D.total() == 14);
  epichead::testing::TempDir dir("epichead_test_camera_rational");
  const std::string path = (dir.path / "calibration.yml").string();
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "image_width" << 640 << "image_height" << 480 << "camera_matrix" << K << "distortion_coefficients" << D;
    fs << "avg_reprojection_error" << rms;
  }
  auto cam = Camera::load(path);
  REQUIRE(cam);
  const std::vector<cv::Point3d> points = points_over_image();
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, expected);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d px = cam->project({points[i].x, points[i].y, points[i].z});
    worst = std::max(worst, (px - Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
  }
  CHECK(worst < 1e-9);
}

TEST_CASE("save writes the shortest of OpenCV's lengths that holds the non-zero coefficients") {
  epichead::testing::TempDir dir("epichead_test_camera_rational");
  const auto saved_length = [&](const Distortion& d) {
    const std::string path = (dir.path / "c.yaml").string();
    REQUIRE(camera(d).save(path));
    return coefficients_in(path);
  };
  CHECK(saved_length(Distortion{}) == 5);
  CHECK(saved_length(Distortion{-0.1, 0.01}) == 5);
  CHECK(saved_length(Distortion{-0.1, 0, 0, 0, 0, 0.2}) == 8);
  CHECK(saved_length(Distortion{0, 0, 0, 0, 0, 0, 0, 0, 0.001}) == 12);
  CHECK(saved_length(Distortion{0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.01}) == 14);
}

namespace {

std::string ros_camera_info(const std::string& model, const std::string& coefficients, int n) {
  return "image_width: 640\nimage_height: 480\ncamera_name: head_camera\ncamera_matrix:\n  rows: 3\n  cols: 3\n"
         "  data: [520.0, 0.0, 318.25, 0.0, 523.5, 243.5, 0.0, 0.0, 1.0]\ndistortion_model: " + model +
         "\ndistortion_coefficients:\n  rows: 1\n  cols: " + std::to_string(n) + "\n  data: [" + coefficients +
         "]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]\n"
         "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [520.0, 0.0, 318.25, 0.0, 0.0, 523.5, 243.5, 0.0, 0.0, 0.0, 1.0, 0.0]\n";
}

}  // namespace

TEST_CASE("a ROS camera_info with distortion_model rational_polynomial loads its 8 coefficients and projects as OpenCV") {
  epichead::testing::TempDir dir("epichead_test_camera_rational");
  auto cam = Camera::load(dir.write("camera_info.yaml",
                                    ros_camera_info("rational_polynomial", "0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082", 8)));
  REQUIRE(cam);
  CHECK(cam->lens() == epichead::vision::LensModel::Pinhole);
  CHECK(cam->distortion() == kRational);
  const std::vector<cv::Point3d> points = points_over_image();
  std::vector<cv::Point2d> expected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), opencv_K(), opencv_D(kRational, 8), expected);
  double worst = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
    worst = std::max(worst, (cam->project({points[i].x, points[i].y, points[i].z}) -
                             Eigen::Vector2d(expected[i].x, expected[i].y)).norm());
  CHECK(worst < 1e-9);
}

TEST_CASE("a coefficient count that is not one of OpenCV's, or not the declared ROS model's, is an error naming the file") {
  epichead::testing::TempDir dir("epichead_test_camera_rational");
  const auto error = [&](const std::string& name, const std::string& text) {
    auto cam = Camera::load(dir.write(name, text));
    REQUIRE_FALSE(cam);
    CHECK_THAT(cam.error(), Catch::StartsWith((dir.path / name).string() + ": "));
    return cam.error();
  };
  const std::string eight = "0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082";
  CHECK_THAT(error("plumb.yaml", ros_camera_info("plumb_bob", eight, 8)),
             Catch::Contains("distortion_model plumb_bob has 5 distortion_coefficients (k1 k2 p1 p2 k3), got 8"));
  CHECK_THAT(error("rational5.yaml", ros_camera_info("rational_polynomial", "0.1, 0.01, 0, 0, 0", 5)),
             Catch::Contains("distortion_model rational_polynomial has 8 distortion_coefficients"));
  CHECK_THAT(error("rational14.yaml", ros_camera_info("rational_polynomial", eight + ", 0, 0, 0, 0, 0, 0", 14)),
             Catch::Contains("got 14"));
  CHECK_THAT(error("rational0.yaml", ros_camera_info("rational_polynomial", "", 0)), Catch::Contains("got none"));
  for (const int n : {1, 2, 3, 6, 7, 9, 10, 11, 13, 15}) {
    INFO(n << " coefficients");
    cv::Mat D = cv::Mat::zeros(1, n, CV_64F);
    D.at<double>(0) = 0.1;
    const std::string path = write_opencv(dir, "count.yaml", D);
    auto cam = Camera::load(path);
    REQUIRE_FALSE(cam);
    CHECK(cam.error() == path + ": distortion_coefficients must have 0, 4, 5, 8, 12 or 14 values (OpenCV's models), got " +
                             std::to_string(n));
  }
  CHECK_THAT(error("nan.yaml", ros_camera_info("rational_polynomial", "0.82, 0.05, 0.0012, .nan, 0.021, 1.12, 0.15, 0.082", 8)),
             Catch::Contains("distortion_coefficients has a non-finite value at (0,3)"));
}
