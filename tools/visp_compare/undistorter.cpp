#include "undistorter.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace epichead::visp_compare {

Undistorter::Undistorter(const vision::Camera& camera) : camera_(camera) {
  if (!camera.has_distortion()) return;
  const auto& k = camera.intrinsics();
  const cv::Matx33d K(k.fx_px, 0, k.cx_px, 0, k.fy_px, k.cy_px, 0, 0, 1);
  const auto& d = camera.distortion();
  const cv::Size size(camera.width_px(), camera.height_px());
  // The tables are computed once; remap per frame is then a lookup.
  if (camera.lens() == vision::LensModel::Fisheye) {
    const cv::Vec4d dist(d[0], d[1], d[2], d[3]);
    cv::fisheye::initUndistortRectifyMap(K, dist, cv::Matx33d::eye(), K, size, CV_16SC2, map1_, map2_);
  } else {
    // All 14 of OpenCV's coefficients (zeros beyond a shorter calibration change nothing).
    const cv::Mat dist(1, static_cast<int>(d.size()), CV_64F, const_cast<double*>(d.data()));
    cv::initUndistortRectifyMap(K, dist, cv::noArray(), K, size, CV_16SC2, map1_, map2_);
  }
}

std::expected<void, std::string> Undistorter::to_grey_undistorted(const cv::Mat& frame, cv::Mat& grey_out) {
  if (frame.depth() != CV_8U)
    return std::unexpected("frame is not 8-bit (OpenCV depth " + std::to_string(frame.depth()) + ")");
  if (frame.cols != camera_.width_px() || frame.rows != camera_.height_px())
    return std::unexpected("frame is " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                           ", camera.yaml says " + std::to_string(camera_.width_px()) + "x" +
                           std::to_string(camera_.height_px()));
  cv::Mat* grey = map1_.empty() ? &grey_out : &grey_;
  switch (frame.channels()) {
    case 1: frame.copyTo(*grey); break;
    case 3: cv::cvtColor(frame, *grey, cv::COLOR_BGR2GRAY); break;
    case 4: cv::cvtColor(frame, *grey, cv::COLOR_BGRA2GRAY); break;
    default: return std::unexpected("frame has " + std::to_string(frame.channels()) + " channels (expected 1, 3 or 4)");
  }
  if (!map1_.empty()) cv::remap(grey_, grey_out, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
  return {};
}

Eigen::Vector2d Undistorter::to_original_px(const Eigen::Vector2d& undistorted_px) const {
  const auto& k = camera_.intrinsics();
  const Eigen::Vector2d xn((undistorted_px.x() - k.cx_px) / k.fx_px, (undistorted_px.y() - k.cy_px) / k.fy_px);
  return camera_.normalized_to_pixel(xn);
}

}  // namespace epichead::visp_compare
