#pragma once
// Tracker lines (EPIC step 2 for circles): 1-px-high windows normal to a projected ellipse,
// spread evenly by arc length over an arc of its contour. All tracker lines of one ellipse are
// the rows of one LineWindow (row r = tracker line r, columns across the contour from inside
// to outside), which is exactly the layout EpicDetector works on: edgels, interval cues,
// likelihoods and reference updates then run unchanged, in one pass over the ellipse.
//
// Column convention: columns increase along the outward normal, so the window's left (low
// columns, ObjectSide::Left) is the inside of the ellipse and ObjectSide::Right the outside.
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/ellipse.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

// One tracker line: centred on the contour point at polar angle polar_rad (about the ellipse
// centre), sampled along the outward unit normal.
struct TrackerLine {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();
  double polar_rad = 0;
};

// Writes `count` tracker lines evenly spread by arc length over `arc` of `ellipse` into out[0..count):
// the whole ellipse gets count lines one step apart all round; an arc gets its first and last
// line on its end points. Returns the spacing in px along the contour (0 when nothing fits).
double spread_tracker_lines(const Ellipse& ellipse, const EllipseArc& arc, int count, TrackerLine* out);

// The tracker line `steps` spacings of `step_px` beyond an arc end (negative: before the begin),
// on the same ellipse: used to watch for the end of an occlusion.
TrackerLine tracker_line_beyond(const Ellipse& ellipse, double polar_rad, double step_px, int direction);

// The window whose rows are tracker lines. Buffers are sized once (max_lines x width_px).
class TrackerLineWindow {
 public:
  explicit TrackerLineWindow(int max_lines = 32, int width_px = 60);
  int max_lines() const { return max_lines_; }
  int width_px() const { return width_px_; }
  // Samples lines[0..n) as rows 0..n (bilinear, all cue channels, borders repeated). False for
  // n outside [2, max_lines] or non-finite lines (then window().geometry().rows = 0).
  bool sample(const WindowImage& image, const TrackerLine* lines, int n);
  const LineWindow& window() const { return window_; }
  // The image point of window row `row` at across-contour offset x_px (0 on the contour).
  Eigen::Vector2d to_image(int row, double x_px) const;

 private:
  bool layout(int rows, bool colour);
  int max_lines_, width_px_;
  LineWindow window_;
  int rows_ = 0;
  bool colour_ = false;
  WindowImage grey_stub_, colour_stub_;  // 2x2 images used to set the window's row layout
  std::vector<TrackerLine> lines_;       // the rows of the last sample
};

}  // namespace epichead::vision
