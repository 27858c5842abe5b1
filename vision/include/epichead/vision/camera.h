#pragma once
// Pinhole camera with OpenCV's 5-coefficient distortion model (k1, k2, p1, p2, k3), or with
// OpenCV's fisheye model (cv::fisheye: equidistant, k1..k4), read from and written to OpenCV
// FileStorage YAML as OpenCV's calibrations write them.
#include <array>
#include <expected>
#include <string>

#include <Eigen/Core>

namespace epichead::vision {

struct Intrinsics {
  double fx_px = 0, fy_px = 0;  // focal lengths in pixels
  double cx_px = 0, cy_px = 0;  // principal point in pixels
};

// OpenCV order: k1, k2, p1, p2, k3; for the fisheye model k1, k2, k3, k4 and a zero.
using Distortion = std::array<double, 5>;

// How a ray is bent onto the image.
//   Pinhole: OpenCV's default model, radial k1 k2 k3 and tangential p1 p2 on x/z, y/z.
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

  // Reads image_width, image_height, camera_matrix (3x3), distortion_coefficients (1x5 or 5x1,
  // or 1x4 / empty meaning zeros beyond). With `fisheye_model: 1` (what cv::fisheye calibration
  // writes beside them) the four coefficients are the fisheye model's k1..k4. Errors name the
  // file and the field. Another camera model (8, 12 or 14 coefficients, a ROS distortion_model
  // other than plumb_bob) is an error, never silently this one.
  static std::expected<Camera, std::string> load(const std::string& yaml_path);
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
};

}  // namespace epichead::vision
