#pragma once
// A line window (EPIC step 2): the image around a projected segment a->b warped so that the line
// runs vertically, sampled bilinearly with all cue channels. Rows run along a->b (sub-sampled by
// a power of two so a long line keeps 20..40 rows), columns run across it at 1 px spacing.
//
// Column convention: column index increases toward ObjectSide::Right of a->b, i.e. along
// (-dy, dx)/L (image y down). So the window's left (low columns) is ObjectSide::Left.
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/window_image.h"

namespace epichead::vision {

// Upper bound on WindowOptions::width_px (per-row scratch lives on the stack).
inline constexpr int kMaxWindowWidth = 256;

struct WindowOptions {
  int width_px = 40;  // samples across the line (the paper's 40 px); 8..kMaxWindowWidth
  int max_rows = 40;  // a line longer than this is sub-sampled by 2^k until rows <= max_rows
  // Interpolate two pixels per 256-bit register where the CPU has AVX2 (checked at run time; the
  // build targets x86-64-v2). The values are the same either way; false keeps the SSE path.
  bool allow_avx2 = true;
};

// Where a window lies in the image: maps window (column, row) back to image pixels.
struct WindowGeometry {
  Eigen::Vector2d a_px = Eigen::Vector2d::Zero();       // start of the segment the window was placed on
  Eigen::Vector2d along = Eigen::Vector2d::UnitY();     // unit vector a->b
  Eigen::Vector2d across = -Eigen::Vector2d::UnitX();   // unit vector of increasing column: (-dy, dx)/L
  double length_px = 0;  // |b - a|
  double step_px = 1;    // row spacing along the line: a power of two
  double s0_px = 0;      // distance from a of row 0 (rows are centred on the segment)
  int rows = 0, cols = 0;
  // Across-line offset of a column from the window's centre line, px (0 on the projected line).
  double x_of_col(double col) const { return col - 0.5 * (cols - 1); }
  // Distance along a->b of a (fractional) row, px.
  double s_of_row(double row) const { return s0_px + row * step_px; }
  // Image point of window coordinates given as (across offset x_px, along distance s_px).
  Eigen::Vector2d to_image(double x_px, double s_px) const { return a_px + s_px * along + x_px * across; }
};

// The sampled window: one float plane per cue channel, row-major with stride cols, sized once for
// the largest window and reused (sampling allocates nothing).
class LineWindow {
 public:
  explicit LineWindow(const WindowOptions& options = {});
  const WindowOptions& options() const { return options_; }
  const WindowGeometry& geometry() const { return geometry_; }
  bool colour() const { return colour_; }
  // Plane of one channel; element (row, col) at [row * cols + col]. Four floats may be loaded
  // from any element (the planes are padded), so SIMD readers need no scalar tail.
  const float* plane(CueChannel c) const { return planes_.data() + static_cast<int>(c) * capacity_; }
  float* plane(CueChannel c) { return planes_.data() + static_cast<int>(c) * capacity_; }

  // Places the window on a->b and samples it. Lines shorter than 20 px keep a 1 px step and get
  // fewer rows (at least 2). Returns false (rows = 0) for a degenerate segment (< 1 px) or
  // non-finite input. Samples beyond the image repeat the border pixel.
  bool sample(const WindowImage& image, const Eigen::Vector2d& a_px, const Eigen::Vector2d& b_px);

 private:
  WindowOptions options_;
  WindowGeometry geometry_;
  bool colour_ = false;
  int capacity_ = 0;  // width_px * max_rows
  std::vector<float> planes_;
};

// Row count and step (power of two) for a segment of length_px under `options`.
struct RowPlan { int rows = 0; double step_px = 1; };
RowPlan plan_rows(double length_px, const WindowOptions& options);

}  // namespace epichead::vision
