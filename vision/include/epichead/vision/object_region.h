#pragma once
// Where the object is in a frame and what colours it has: the model drawn at a pose fills the
// object's region, and the pixels well inside and well outside it give an object and a
// background colour histogram. Edge windows use it on the object's outline (where one side of
// the edge leaves the object): there the side away from the object must look like background.
// That tells the object's own outline from a printed edge parallel to it just inside (a can's
// rim from the lower border of its label: both have the object's colours on their inner side,
// but only the rim has background beyond it). The references of the cue integration cannot tell
// them before they are learnt, on the first frame and after a loss, when the start may be off
// by more than the two edges lie apart.
#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/cues.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

struct ObjectRegionOptions {
  // The object's colours are sampled deeper inside the drawn outline than this. Small: the
  // bands along the outline (a can's foot and lid ring) are the colours that matter most there;
  // the strip of background a start error draws inside only blurs the histogram a little.
  double inner_margin_px = 2;
  // The background's colours are sampled further outside than this: the pose the model was
  // drawn from may be off by about a search window's half width, and the object's own colours
  // in the background histogram would make its outline look like a printed edge.
  double outer_margin_px = 12;
  // The background is the ring beyond the outer margin, this wide.
  double ring_px = 24;
  // Fewer object or background samples than this: no colour model (no evidence either way).
  int min_samples = 200;
  // How far off the outline the region is probed to tell which side of an edge leaves it.
  double probe_px = 3;
};

class ObjectRegion {
 public:
  explicit ObjectRegion(const ObjectRegionOptions& options = {});

  // Draws the model at cam_T_obj (faces, rims, cylinders) and learns the colours of the frame
  // inside and around it. Returns ready(). Half a millisecond for the can at 640x480 (`epichead
  // bench object_region_can`); it allocates (OpenCV's drawing and distance transforms), which
  // is why it runs only on the frames that settle, never in steady tracking.
  bool learn(const WindowImage& image, const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj);
  void clear() { ready_ = false; }
  bool ready() const { return ready_; }

  // Which side of an edge at point_px, with the window's columns growing along dir, leaves the
  // drawn object: +1 the side dir points to, -1 the other, 0 both or neither (not the outline).
  std::int8_t outer_side(const Eigen::Vector2d& point_px, const Eigen::Vector2d& dir) const;
  // P(object | the interval's intensity and chromaticity), from the two histograms; 0.5 for an
  // invalid interval (no evidence).
  float object_probability(const IntervalCues& cues) const;

 private:
  static constexpr int kBins = 8;  // per channel: intensity, chromaticity r, chromaticity g
  static int bin(float v) { return std::clamp(static_cast<int>(v * (kBins / 256.0f)), 0, kBins - 1); }
  ObjectRegionOptions options_;
  bool ready_ = false;
  cv::Mat mask_, not_mask_;                  // CV_8U: the drawn object and its complement
  cv::Mat inside_px_, outside_px_;           // CV_32F: distance to the outline, inside and outside (drawn box)
  std::vector<cv::Point> polygon_, hull_;    // scratch for drawing
  std::array<float, kBins * kBins * kBins> p_object_{};
};

}  // namespace epichead::vision
