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
  // The margins below are distances, not negative.
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

  // Sizes the buffers for frames of this size and touches their pages, so that the first
  // learn() neither allocates nor page-faults (that was 5 of the first frame's 6 ms on the real
  // tea box video). Optional: learn() sizes them itself for a frame of another size.
  void reserve(int width_px, int height_px);

  // Draws the model at cam_T_obj (faces, rims, cylinders) and learns the colours of the frame
  // inside and around it. Returns ready(). It runs on the frames that settle, never in steady
  // tracking (`epichead bench object_region` for its cost). After reserve() for the frame's size
  // it allocates nothing but what OpenCV's convex hull and polygon fill may.
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
  using Histogram = std::array<int, kBins * kBins * kBins>;
  // Draws the model into mask_ and returns the box of what was drawn, clipped to the frame
  // (empty when nothing was).
  cv::Rect draw(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj);
  // Counts the colours of the pixels of the sampling grid (every second pixel of box, from its
  // corner) whose distance to the drawn outline lies in (min_px, max_px]: inside the object, or
  // outside it. Distances are computed over region, a part of box.
  int count(const WindowImage& image, const cv::Rect& box, const cv::Rect& region, bool inside, float min_px,
            float max_px, Histogram& histogram);

  ObjectRegionOptions options_;
  bool ready_ = false;
  cv::Mat mask_;                             // CV_8U, the frame's size: the drawn object (255)
  cv::Rect dirty_;                           // where mask_ may be non-zero
  std::vector<std::int32_t> distance_;       // chamfer distances of one region, with a border
  std::vector<cv::Point> polygon_, hull_;    // scratch for drawing
  Histogram object_{}, background_{};
  std::array<float, kBins * kBins * kBins> p_object_{};
};

}  // namespace epichead::vision
