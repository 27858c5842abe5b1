#include "epichead/vision/edgels.h"

#include <algorithm>
#include <cmath>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace epichead::vision {

void EdgelSet::reserve(const WindowOptions& options) {
  const int cols = std::clamp(options.width_px, 8, kMaxWindowWidth), rows = std::max(options.max_rows, 2);
  // Maxima are at least two columns apart (strict on one side), so cols / 2 per row at most.
  reserve_touched(edgels, static_cast<std::size_t>(rows) * (cols / 2 + 1));
  reserve_touched(row_begin, static_cast<std::size_t>(rows) + 1);
  gradient.resize(static_cast<std::size_t>(rows) * cols);
}

void find_edgels(const LineWindow& window, const EdgelOptions& options, EdgelSet& out) {
  const WindowGeometry& g = window.geometry();
  out.edgels.clear();
  out.row_begin.clear();
  out.rows = g.rows;
  if (g.rows == 0) { out.row_begin.push_back(0); return; }
  const int cols = g.cols, rows = g.rows;
  if (out.gradient.size() < static_cast<std::size_t>(rows) * cols) out.gradient.resize(static_cast<std::size_t>(rows) * cols);
  const float* I = window.plane(CueChannel::Intensity);
  float* G = out.gradient.data();
  // Central difference across each row (columns 0 and cols-1 left at 0).
  for (int r = 0; r < rows; ++r) {
    const float* in = I + r * cols;
    float* d = G + r * cols;
    d[0] = 0;
    d[cols - 1] = 0;
    for (int c = 1; c < cols - 1; ++c) d[c] = 0.5f * (in[c + 1] - in[c - 1]);
  }
  // [1 2 1] / 4 along the line, in place, top-down: `carry` holds the previous row's
  // unsmoothed values (row -1 and row `rows` replicate the border rows).
  const float min_g = options.min_gradient;
  const float x_centre = 0.5f * static_cast<float>(cols - 1);
  out.row_begin.resize(static_cast<std::size_t>(rows) + 1);  // within the reserved capacity
  float carry[kMaxWindowWidth];
  for (int c = 0; c < cols; ++c) carry[c] = G[c];
  for (int r = 0; r < rows; ++r) {
    float* d = G + r * cols;
    const float* next = G + std::min(r + 1, rows - 1) * cols;  // not yet smoothed
    for (int c = 0; c < cols; ++c) {
      const float cur = d[c];
      const float smoothed = 0.25f * (carry[c] + 2.0f * cur + next[c]);
      carry[c] = cur;
      d[c] = smoothed;
    }
  }
  for (int r = 0; r < rows; ++r) {
    out.row_begin[r] = static_cast<int>(out.edgels.size());
    const float* d = G + r * cols;
    const float s = static_cast<float>(g.s_of_row(r));
    auto add = [&](int c) {
      const float a = std::fabs(d[c]);
      const float l = std::fabs(d[c - 1]), rr = std::fabs(d[c + 1]);
      const float den = l - 2.0f * a + rr;
      float off = den < 0 ? 0.5f * (l - rr) / den : 0.0f;
      off = std::clamp(off, -0.5f, 0.5f);
      // Built in place: a copy of the 28-byte struct from the stack reloaded 16 bytes that two
      // narrower stores had just written (a store-forwarding stall on every edgel).
      Edgel& e = out.edgels.emplace_back();
      e.col = static_cast<float>(c) + off;
      e.x_px = e.col - x_centre;
      e.s_px = s;
      e.gradient = d[c];
      e.row = r;
    };
    auto is_max = [&](int c) {
      const float a = std::fabs(d[c]);
      return a >= min_g && a > std::fabs(d[c - 1]) && a >= std::fabs(d[c + 1]);
    };
    int c = 2;
#if defined(__SSE2__)
    // Four columns per test; most columns are not maxima, so the scalar work is per edgel.
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFFFFFF)), vmin = _mm_set1_ps(min_g);
    for (; c + 4 <= cols - 2; c += 4) {
      const __m128 a = _mm_and_ps(abs_mask, _mm_loadu_ps(d + c));
      const __m128 l = _mm_and_ps(abs_mask, _mm_loadu_ps(d + c - 1));
      const __m128 rr = _mm_and_ps(abs_mask, _mm_loadu_ps(d + c + 1));
      const __m128 hit = _mm_and_ps(_mm_cmpge_ps(a, vmin), _mm_and_ps(_mm_cmpgt_ps(a, l), _mm_cmpge_ps(a, rr)));
      for (int bits = _mm_movemask_ps(hit); bits != 0; bits &= bits - 1) add(c + __builtin_ctz(bits));
    }
#endif
    for (; c < cols - 2; ++c)
      if (is_max(c)) add(c);
  }
  out.row_begin[rows] = static_cast<int>(out.edgels.size());
}

}  // namespace epichead::vision
