#pragma once
// Edgels (EPIC step 3a): in every window row, the local maxima of the intensity gradient across
// the line, with sub-pixel position. The interval of cue values either side of each edgel is
// computed by cues.h; the likelihood is filled in by epic.h.
#include <vector>

#include "epichead/vision/line_window.h"

namespace epichead::vision {

struct EdgelOptions {
  // Noise floor on |dI/dx| (grey levels per px, smoothed central difference). The one
  // threshold of edgel detection: 8-bit camera noise is 1-2 grey levels, the smoothed derivative
  // has about half that deviation, so 4 is ~4 sigma of noise and far below any visible edge.
  float min_gradient = 4.0f;
};

struct Edgel {
  float col = 0;        // sub-pixel column in the window
  float x_px = 0;       // across-line offset from the window centre line, px
  float s_px = 0;       // distance along a->b, px
  float gradient = 0;   // signed dI/dx at the maximum (x = column direction)
  float likelihood = 0; // EPIC likelihood l_k in [0, 1] (0 until computed)
  int row = 0;
  int left_interval = 0;  // index of the interval on its left (lower columns); right is +1
};

// Reserves n elements of v and writes them once, so that the pages are mapped now, at set-up,
// and not on the first frame that fills them (a page fault costs microseconds).
template <typename T>
void reserve_touched(std::vector<T>& v, std::size_t n) {
  if (v.capacity() >= n) return;
  v.reserve(n);
  v.resize(n);
  v.clear();
}

// All edgels of a window, row by row, in contiguous storage reserved once.
struct EdgelSet {
  std::vector<Edgel> edgels;   // ordered by row, then by column
  std::vector<int> row_begin;  // edgels of row r: [row_begin[r], row_begin[r + 1])
  std::vector<float> gradient; // scratch: per-pixel smoothed dI/dx, rows x cols
  int rows = 0;
  // Sizes the buffers for the largest window so that detection allocates nothing.
  void reserve(const WindowOptions& options);
};

// Detects the edgels of every row of `window`. Gradient: central difference across the row,
// smoothed [1 2 1] / 4 along the line (the line is near-vertical, so this averages along the
// edge and not across it). Maxima need |g| >= min_gradient, are strict on the left and
// non-strict on the right (a two-sample plateau yields one edgel), and lie in columns
// [2, cols - 3] so the parabola has both neighbours. Sub-pixel: vertex of the parabola
// through |g| at col - 1, col, col + 1.
void find_edgels(const LineWindow& window, const EdgelOptions& options, EdgelSet& out);

}  // namespace epichead::vision
