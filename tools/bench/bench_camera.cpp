// Benchmarks camera_project_*, camera_jacobian_* and camera_unproject_*: the camera model's
// per-point work (projection of model points and edgels, the pose estimator's Jacobian, the
// inverse for rays), 256 points across the image per iteration. _k5 is OpenCV's default model
// (k1 k2 p1 p2 k3), the one most calibrations have; _k14 has every term of cv::projectPoints
// (rational k4..k6, thin prism s1..s4, sensor tilt).
#include <memory>
#include <vector>

#include "bench/bench.h"
#include "epichead/vision/camera.h"

namespace {

using namespace epichead::vision;

constexpr int kPoints = 256;

struct CameraBench {
  Camera camera;
  std::vector<Eigen::Vector3d> points;   // camera frame, spread over the image
  std::vector<Eigen::Vector2d> normalized;
  std::vector<Eigen::Vector2d> pixels;
  Eigen::Vector2d sum_px = Eigen::Vector2d::Zero();
  Eigen::Matrix2d sum_J = Eigen::Matrix2d::Zero();
  Eigen::Vector3d sum_ray = Eigen::Vector3d::Zero();
};

std::shared_ptr<CameraBench> make(const Camera& camera) {
  auto b = std::make_shared<CameraBench>();
  b->camera = camera;
  for (int i = 0; i < kPoints; ++i) {
    const double x = -0.5 + (i % 16) / 15.0, y = -0.375 + (i / 16) / 20.0;  // about the 640x480 image
    const double z = 0.5 + 0.01 * i;
    b->points.emplace_back(x * z, y * z, z);
    b->normalized.emplace_back(x, y);
    b->pixels.push_back(camera.normalized_to_pixel({x, y}));
  }
  return b;
}

void add(const char* name, Camera (*camera)()) {
  using epichead::bench::Registration;
  static std::vector<Registration> registrations;
  const std::string suffix(name);
  registrations.emplace_back("camera_project_" + suffix, [camera] {
    auto b = make(camera());
    return [b] {
      for (const Eigen::Vector3d& p : b->points) b->sum_px += b->camera.project(p);
    };
  }, kPoints);
  registrations.emplace_back("camera_jacobian_" + suffix, [camera] {
    auto b = make(camera());
    return [b] {
      for (const Eigen::Vector2d& xn : b->normalized) b->sum_J += b->camera.normalized_to_pixel_jacobian(xn);
    };
  }, kPoints);
  registrations.emplace_back("camera_unproject_" + suffix, [camera] {
    auto b = make(camera());
    return [b] {
      for (const Eigen::Vector2d& px : b->pixels) b->sum_ray += b->camera.unproject(px);
    };
  }, kPoints);
}

// A typical webcam calibration: barrel distortion and small tangential terms.
Camera k5_camera() { return Camera(640, 480, {600, 602, 321.5, 238.25}, Distortion{-0.28, 0.09, 0.001, -0.0007, -0.012}); }

// A wide-angle lens calibrated with CALIB_RATIONAL_MODEL | CALIB_THIN_PRISM_MODEL | CALIB_TILTED_MODEL.
Camera k14_camera() {
  return Camera(640, 480, {520, 523.5, 318.25, 243.5},
                Distortion{0.82, 0.05, 0.0012, -0.0006, 0.021, 1.12, 0.15, 0.082, 0.0021, -0.0004, -0.0015, 0.0003,
                           0.012, -0.021});
}

const bool registered = [] {
  add("k5", k5_camera);
  add("k14", k14_camera);
  return true;
}();

}  // namespace
