#pragma once
// Frames of a sequence turned into what ViSP's tracker takes: grey, without lens distortion.
// ViSP's camera model has one radial coefficient, not OpenCV's five, so the image is
// undistorted with OpenCV and ViSP is given the plain pinhole of the result.
#include <expected>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"

namespace epichead::visp_compare {

class Undistorter {
 public:
  // The undistorted image keeps the camera matrix K (same size), so a pixel of it is the
  // pinhole projection with K; its corners lose the pixels that fall outside.
  explicit Undistorter(const vision::Camera& camera);

  // Intrinsics of the undistorted image: what ViSP is told.
  vision::Intrinsics pinhole() const { return camera_.intrinsics(); }

  // frame: 8-bit, 1, 3 (BGR) or 4 (BGRA) channels of the camera's size. grey_out is reused.
  std::expected<void, std::string> to_grey_undistorted(const cv::Mat& frame, cv::Mat& grey_out);

  // A pixel of the undistorted image -> the same ray's pixel in the original frame.
  Eigen::Vector2d to_original_px(const Eigen::Vector2d& undistorted_px) const;

 private:
  vision::Camera camera_;
  cv::Mat map1_, map2_;  // remap tables, empty when the camera has no distortion
  cv::Mat grey_;         // scratch
};

}  // namespace epichead::visp_compare
