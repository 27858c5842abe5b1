#pragma once
// How far the content of an image region moved from the previous frame to this one: the
// translation that best aligns the two frames inside the region, by phase correlation (the
// normalised cross-power spectrum's peak, on OpenCV's DFT). Without an IMU it is what the image
// itself says about a burst of camera motion, which a constant-velocity prediction cannot know: a hand-held shake moves the
// object 20-60 px between two frames, beyond the reach of the tracker's windows.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace cv::hal {
class DFT2D;
}

namespace epichead::vision {

struct RegionShift {
  Eigen::Vector2d shift_px = Eigen::Vector2d::Zero();  // this frame's content = previous frame's + shift
  double response = 0;  // the correlation's peak (0..1): how much of the region moved as one
};

class RegionShiftEstimator {
 public:
  RegionShiftEstimator();
  // Not copyable: a copy would share the DFT's plan, whose work buffers are not for two threads.
  RegionShiftEstimator(const RegionShiftEstimator&) = delete;
  RegionShiftEstimator& operator=(const RegionShiftEstimator&) = delete;
  RegionShiftEstimator(RegionShiftEstimator&&) = default;
  RegionShiftEstimator& operator=(RegionShiftEstimator&&) = default;
  // Keeps the frame (8-bit, 1, 3 or 4 channels) as the next call's previous frame, and returns
  // the shift of `region_px` (a rectangle of the previous frame) since the previous frame:
  // nothing for the first frame, a frame of another size, or a region too small to correlate.
  // The region (at least 32 px a side) is shrunk to 64 x 64 before correlating (the shifts it
  // is for are tens of pixels), and may move up to half its size. After the first frame of a
  // size, calls allocate nothing.
  std::optional<RegionShift> push(const cv::Mat& frame, const cv::Rect& region_px);
  // Forgets the previous frame (the next push() only keeps its frame).
  void reset() { have_previous_ = false; }

 private:
  cv::Mat previous_;         // the previous frame, as given
  std::vector<float> columns_;  // scratch: one row of grey sums, the frame's width
  cv::Mat window_;           // the Hanning window of the correlated size
  cv::Mat a_, b_;            // the region of each frame, shrunk, grey, windowed
  cv::Mat spectrum_a_, spectrum_b_, cross_, surface_;
  cv::Ptr<cv::hal::DFT2D> forward_, inverse_;  // the DFT planned for the correlated size
  bool have_previous_ = false;
};

}  // namespace epichead::vision
