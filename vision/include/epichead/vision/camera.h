#pragma once
// Pinhole camera with OpenCV's distortion model (cv::projectPoints: k1 k2 p1 p2 k3, and the
// rational k4 k5 k6, thin-prism s1..s4 and tilted-sensor taux tauy terms), or with OpenCV's
// fisheye model (cv::fisheye: equidistant, k1..k4), read from OpenCV FileStorage YAML as
// OpenCV's calibrations write them or from ROS camera_info YAML, and written as OpenCV does.
#include <array>
#include <cstdint>
#include <expected>
#include <string>

#include <Eigen/Core>

namespace epichead::vision {

struct Intrinsics {
  double fx_px = 0, fy_px = 0;  // focal lengths in pixels
  double cx_px = 0, cy_px = 0;  // principal point in pixels
};

// OpenCV's distCoeffs order: k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 taux tauy (a calibration with
// 4, 5, 8 or 12 of them has zeros beyond); for the fisheye model k1 k2 k3 k4 and zeros.
using Distortion = std::array<double, 14>;

// How a ray is bent onto the image.
//   Pinhole: OpenCV's model on x = X/Z, y = Y/Z, r^2 = x^2 + y^2:
//            radial (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6),
//            tangential p1 p2, thin prism s1 s2 (x) and s3 s4 (y), then the sensor tilt
//            (taux, tauy in radians) as cv::projectPoints applies it.
//   Fisheye: cv::fisheye's, on the angle theta of the ray from the axis:
//            theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
enum class LensModel { Pinhole, Fisheye };

class Camera {
 public:
  Camera() = default;
  // Throws std::invalid_argument on non-positive sizes or focal lengths (a programming error
  // here; input from files goes through load(), which returns an error instead).
  Camera(int width_px, int height_px, const Intrinsics& k, const Distortion& distortion = {},
         LensModel lens = LensModel::Pinhole);

  // Reads image_width, image_height, camera_matrix (3x3), distortion_coefficients (a row or
  // column of 4, 5, 8, 12 or 14 values, OpenCV's distCoeffs lengths, or empty meaning none).
  // With `fisheye_model: 1` (what cv::fisheye calibration writes beside them) the four
  // coefficients are the fisheye model's k1..k4. A ROS camera_info file names its model:
  // plumb_bob (5 values, or 4), rational_polynomial (8), equidistant (4). Errors name the file
  // and the field. Another camera model (a ROS distortion_model not listed, another count) is
  // an error, never silently one of these.
  static std::expected<Camera, std::string> load(const std::string& yaml_path);
  // Writes OpenCV's layout with the shortest distCoeffs length (5, 8, 12, 14; fisheye 4) that
  // holds every non-zero coefficient, so that a 5-coefficient camera writes what it always did.
  std::expected<void, std::string> save(const std::string& yaml_path) const;

  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  const Intrinsics& intrinsics() const { return k_; }
  const Distortion& distortion() const { return dist_; }
  bool has_distortion() const { return has_distortion_; }
  LensModel lens() const { return lens_; }
  Eigen::Matrix3d K() const;

  // Normalised coordinates (x/z, y/z) -> pixel, applying the distortion.
  Eigen::Vector2d normalized_to_pixel(const Eigen::Vector2d& xn) const;
  // Derivative of normalized_to_pixel at xn (for Gauss-Newton on pixel residuals).
  Eigen::Matrix2d normalized_to_pixel_jacobian(const Eigen::Vector2d& xn) const;
  // Pixel -> normalised coordinates, undoing the distortion by fixed-point iteration.
  Eigen::Vector2d pixel_to_normalized(const Eigen::Vector2d& px) const;
  // Camera-frame point (z > 0) -> pixel.
  Eigen::Vector2d project(const Eigen::Vector3d& p_cam) const;
  // Pixel -> ray direction with z = 1 in the camera frame.
  Eigen::Vector3d unproject(const Eigen::Vector2d& px) const;
  // True when the pixel lies inside the image (with an optional margin in pixels).
  bool in_image(const Eigen::Vector2d& px, double margin_px = 0) const;

 private:
  int width_px_ = 0, height_px_ = 0;
  Intrinsics k_;
  Distortion dist_{};
  bool has_distortion_ = false;
  LensModel lens_ = LensModel::Pinhole;
  // Which code path projects: the common 5-coefficient model keeps its short path; the
  // rational, thin-prism and tilt terms cost only the cameras that have them.
  enum class Path : std::uint8_t { Ideal, Brown, Full, Fisheye };
  Path path_ = Path::Ideal;
  bool tilted_ = false;
  Eigen::Matrix3d tilt_ = Eigen::Matrix3d::Identity();  // OpenCV's tilt projection, from taux tauy
};

}  // namespace epichead::vision
