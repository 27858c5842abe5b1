#pragma once
// How far the content of an image region moved from the previous frame to this one: the
// translation that best aligns the two frames inside the region, by phase correlation (the
// normalised cross-power spectrum's peak, on OpenCV's DFT). Without an IMU it is what the image
// itself says about a burst of camera motion, which a constant-velocity prediction cannot know: a hand-held shake moves the
// object 20-60 px between two frames, beyond the reach of the tracker's windows.
#include <optional>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace epichead::vision {

struct RegionShift {
  Eigen::Vector2d shift_px = Eigen::Vector2d::Zero();  // this frame's content = previous frame's + shift
  double response = 0;  // the correlation's peak (0..1): how much of the region moved as one
};

class RegionShiftEstimator {
 public:
  // Keeps the frame (8-bit, 1, 3 or 4 channels) as the next call's previous frame, and returns
  // the shift of `region_px` (a rectangle of the previous frame) since the previous frame:
  // nothing for the first frame, a frame of another size, or a region too small to correlate.
  // The region is halved before correlating (the shifts it is for are tens of pixels), and may
  // move up to half its size. After the first frame of a size, same-sized calls allocate
  // nothing but what the DFT itself takes.
  std::optional<RegionShift> push(const cv::Mat& frame, const cv::Rect& region_px);
  // Forgets the previous frame (the next push() only keeps its frame).
  void reset() { have_previous_ = false; }

 private:
  cv::Mat previous_;       // the previous frame, as given
  cv::Mat grey_, full_;    // scratch: the region grey, and as floats before it is halved
  cv::Mat window_;         // the Hanning window of the halved region's size
  cv::Mat a_, b_;          // the region of each frame, grey and halved, as floats
  cv::Mat spectrum_a_, spectrum_b_, cross_, surface_;
  bool have_previous_ = false;
};

}  // namespace epichead::vision
