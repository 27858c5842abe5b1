#include "epichead/vision/line_window.h"

#include <algorithm>
#include <cmath>

#include <cstdint>

#if defined(__SSE4_1__)
#include <immintrin.h>
#endif

namespace epichead::vision {

namespace {

#if defined(__SSE4_1__) && defined(__GNUC__) && defined(__x86_64__)
#define EPICHEAD_WARP_AVX2 1
// Two 4-float vectors (one pixel's channels each) in the halves of one register.
__attribute__((target("avx2"))) inline __m256 pair_of(const float* lo, const float* hi) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(lo)), _mm_loadu_ps(hi), 1);
}
// f[0] in the low half's four lanes, f[1] in the high half's.
__attribute__((target("avx2"))) inline __m256 spread_of(const float* f) {
  return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_broadcast_ss(f)), _mm_broadcast_ss(f + 1), 1);
}
// The second pass of a row (see sample()), two taps per 256-bit register where the CPU has AVX2
// (the build targets x86-64-v2): the same operations per lane in the same order, so the same
// values, with half the vector arithmetic, which bounds this pass. No FMA: a fused multiply-add
// would round differently.
__attribute__((target("avx2"))) void row_taps_avx2(const float* px, std::size_t stride, const std::int32_t* off,
                                                   const float* fxs, const float* fys, int groups, float* pi,
                                                   float* pr, float* pg, float* pt) {
  for (int c = 0; c < groups; c += 4) {
    __m128 v[4];
    for (int k = 0; k < 4; k += 2) {
      const float* q0 = px + off[c + k];
      const float* r0 = px + off[c + k + 1];
      const __m256 vfx = spread_of(fxs + c + k), vfy = spread_of(fys + c + k);
      const __m256 a0 = pair_of(q0, r0), b0 = pair_of(q0 + 4, r0 + 4);
      const __m256 a1 = pair_of(q0 + stride, r0 + stride), b1 = pair_of(q0 + stride + 4, r0 + stride + 4);
      const __m256 top = _mm256_add_ps(a0, _mm256_mul_ps(vfx, _mm256_sub_ps(b0, a0)));
      const __m256 bot = _mm256_add_ps(a1, _mm256_mul_ps(vfx, _mm256_sub_ps(b1, a1)));
      const __m256 both = _mm256_add_ps(top, _mm256_mul_ps(vfy, _mm256_sub_ps(bot, top)));
      v[k] = _mm256_castps256_ps128(both);
      v[k + 1] = _mm256_extractf128_ps(both, 1);
    }
    _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);
    _mm_storeu_ps(pi + c, v[0]);
    _mm_storeu_ps(pr + c, v[1]);
    _mm_storeu_ps(pg + c, v[2]);
    _mm_storeu_ps(pt + c, v[3]);
  }
}
const bool kHaveAvx2 = __builtin_cpu_supports("avx2");
#endif

#if defined(__SSE4_1__)
// Requests the source lines of a window row starting at (x1, y1) ahead of its taps: one prefetch
// per cache line and image row, every `step`-th sample (see sample()).
inline void prefetch_row(const float* px, std::size_t stride, int w, float x1, float y1, float ax, float ay, int cols,
                         int step) {
  for (int q = 0; q < cols; q += step) {
    const int ix = static_cast<int>(x1 + static_cast<float>(q) * ax), iy = static_cast<int>(y1 + static_cast<float>(q) * ay);
    const char* a = reinterpret_cast<const char*>(px + 4 * (static_cast<std::size_t>(iy) * w + ix));
    _mm_prefetch(a, _MM_HINT_T0);
    _mm_prefetch(a + stride * sizeof(float), _MM_HINT_T0);
  }
}

// The first pass of a row (see sample()): the image offset (in floats) and the bilinear
// fractions of columns [0, groups), four per register; clamped into the image unless the whole
// window is inside.
inline void row_offsets(float x0, float y0, float ax, float ay, bool inside, float xmax, float ymax, int w, int groups,
                        std::int32_t* off, float* fxs, float* fys) {
  const __m128 vx0 = _mm_set1_ps(x0), vy0 = _mm_set1_ps(y0);
  const __m128 vax = _mm_set1_ps(ax), vay = _mm_set1_ps(ay);
  const __m128 vxmax = _mm_set1_ps(xmax), vymax = _mm_set1_ps(ymax), zero = _mm_setzero_ps();
  const __m128i vw = _mm_set1_epi32(w);
  // Column numbers as floats, stepped by 4 (exact: small integers).
  __m128 vc = _mm_setr_ps(0.0f, 1.0f, 2.0f, 3.0f);
  const __m128 four = _mm_set1_ps(4.0f);
  for (int q = 0; q < groups; q += 4, vc = _mm_add_ps(vc, four)) {
    __m128 x = _mm_add_ps(vx0, _mm_mul_ps(vc, vax)), y = _mm_add_ps(vy0, _mm_mul_ps(vc, vay));
    if (!inside) {
      x = _mm_min_ps(_mm_max_ps(x, zero), vxmax);
      y = _mm_min_ps(_mm_max_ps(y, zero), vymax);
    }
    const __m128i ix = _mm_cvttps_epi32(x), iy = _mm_cvttps_epi32(y);
    _mm_store_ps(fxs + q, _mm_sub_ps(x, _mm_cvtepi32_ps(ix)));
    _mm_store_ps(fys + q, _mm_sub_ps(y, _mm_cvtepi32_ps(iy)));
    _mm_store_si128(reinterpret_cast<__m128i*>(off + q), _mm_slli_epi32(_mm_add_epi32(_mm_mullo_epi32(iy, vw), ix), 2));
  }
}

// The second pass of a row, columns [c, groups): four all-channel taps at a time and a 4x4
// transpose into the four planes (pi.. point at the row's first column), with the scalar tap's
// arithmetic, so the same values.
inline void row_taps(const float* px, std::size_t stride, const std::int32_t* off, const float* fxs, const float* fys,
                     int c, int groups, float* pi, float* pr, float* pg, float* pt) {
  for (; c < groups; c += 4) {
    __m128 v[4];
    for (int k = 0; k < 4; ++k) {
      const float* q0 = px + off[c + k];
      const float* q1 = q0 + stride;
      const __m128 vfx = _mm_load1_ps(fxs + c + k), vfy = _mm_load1_ps(fys + c + k);
      const __m128 a0 = _mm_loadu_ps(q0), b0 = _mm_loadu_ps(q0 + 4);
      const __m128 a1 = _mm_loadu_ps(q1), b1 = _mm_loadu_ps(q1 + 4);
      const __m128 top = _mm_add_ps(a0, _mm_mul_ps(vfx, _mm_sub_ps(b0, a0)));
      const __m128 bot = _mm_add_ps(a1, _mm_mul_ps(vfx, _mm_sub_ps(b1, a1)));
      v[k] = _mm_add_ps(top, _mm_mul_ps(vfy, _mm_sub_ps(bot, top)));
    }
    _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);
    _mm_storeu_ps(pi + c, v[0]);
    _mm_storeu_ps(pr + c, v[1]);
    _mm_storeu_ps(pg + c, v[2]);
    _mm_storeu_ps(pt + c, v[3]);
  }
}
#endif

}  // namespace

RowPlan plan_rows(double length_px, const WindowOptions& options) {
  RowPlan plan;
  if (!std::isfinite(length_px) || length_px < 1.0) return plan;
  const int max_rows = std::max(2, options.max_rows);
  // Smallest power of two that brings the row count to max_rows or below; for a line longer
  // than max_rows this leaves at least max_rows / 2 rows (20..40 with the default).
  double step = 1;
  while (length_px / step > max_rows && step < 1e6) step *= 2;
  plan.step_px = step;
  plan.rows = std::clamp(static_cast<int>(std::floor(length_px / step)), 2, max_rows);
  return plan;
}

LineWindow::LineWindow(const WindowOptions& options) : options_(options) {
  options_.width_px = std::clamp(options_.width_px, 8, kMaxWindowWidth);
  options_.max_rows = std::max(options_.max_rows, 2);
  capacity_ = options_.width_px * options_.max_rows;
  // Padded by 4 floats so that a reader may load 4 floats from any element (see plane()).
  planes_.assign(static_cast<std::size_t>(kCueChannels) * capacity_ + 4, 0.0f);
}

bool LineWindow::sample(const WindowImage& image, const Eigen::Vector2d& a_px, const Eigen::Vector2d& b_px) {
  geometry_.rows = 0;
  colour_ = image.colour();
  const Eigen::Vector2d d = b_px - a_px;
  const double length = d.norm();
  if (!a_px.allFinite() || !b_px.allFinite() || image.width_px() < 2 || image.height_px() < 2) return false;
  const RowPlan plan = plan_rows(length, options_);
  if (plan.rows == 0) return false;
  WindowGeometry& g = geometry_;
  g.a_px = a_px;
  g.along = d / length;
  g.across = Eigen::Vector2d(-g.along.y(), g.along.x());  // toward ObjectSide::Right
  g.length_px = length;
  g.step_px = plan.step_px;
  g.s0_px = 0.5 * (length - (plan.rows - 1) * plan.step_px);
  g.cols = options_.width_px;
  g.rows = plan.rows;

  const int w = image.width_px(), h = image.height_px();
  const float* px = image.pixels();
  float* pi = plane(CueChannel::Intensity);
  float* pr = plane(CueChannel::ChromaR);
  float* pg = plane(CueChannel::ChromaG);
  float* pt = plane(CueChannel::Texture);
  const float ax = static_cast<float>(g.across.x()), ay = static_cast<float>(g.across.y());
  // The window is a parallelogram: inside the image (with the +1 bilinear neighbour) when its
  // four corners are. Then no per-pixel clamp is needed.
  bool inside = true;
  for (int r : {0, g.rows - 1})
    for (int c : {0, g.cols - 1}) {
      const Eigen::Vector2d p = g.to_image(g.x_of_col(c), g.s_of_row(r));
      inside = inside && p.x() >= 0 && p.y() >= 0 && p.x() < w - 1.01 && p.y() < h - 1.01;
    }
  const float xmax = static_cast<float>(w - 1) - 1e-3f, ymax = static_cast<float>(h - 1) - 1e-3f;
  const std::size_t stride = 4 * static_cast<std::size_t>(w);
  // Prefetching (see the row loop) pays only on frames larger than a typical per-core L2. Its
  // step: the samples per 64-byte line (4 pixels of 4 floats) along x and per image row along y.
  constexpr std::size_t kCacheResidentBytes = 512 * 1024;
  const bool prefetch = inside && 4 * sizeof(float) * static_cast<std::size_t>(w) * h > kCacheResidentBytes;
  const float fax = std::fabs(ax), fay = std::fabs(ay);
  const int prefetch_step = std::clamp(static_cast<int>(std::min(4.0f / std::max(fax, 1e-3f), 1.0f / std::max(fay, 1e-3f))), 1, 4);
  // One bilinear tap: all four channels in one register, lerp along x on both rows, then along y.
  auto tap = [&](float x, float y, float v[4]) {
    const int ix = static_cast<int>(x), iy = static_cast<int>(y);  // x, y >= 0: truncation floors
    const float fx = x - static_cast<float>(ix), fy = y - static_cast<float>(iy);
    const float* q0 = px + 4 * (static_cast<std::size_t>(iy) * w + ix);
    const float* q1 = q0 + stride;
    for (int k = 0; k < 4; ++k) {
      const float t = q0[k] + fx * (q0[4 + k] - q0[k]), b = q1[k] + fx * (q1[4 + k] - q1[k]);
      v[k] = t + fy * (b - t);
    }
  };
  for (int r = 0; r < g.rows; ++r) {
    const Eigen::Vector2d p0 = g.to_image(g.x_of_col(0), g.s_of_row(r));
    const float x0 = static_cast<float>(p0.x()), y0 = static_cast<float>(p0.y());
    const int base = r * g.cols;
    const float last = static_cast<float>(g.cols - 1);
    image.prepare_span(x0, y0, x0 + last * ax, y0 + last * ay);  // the columns' extremes, as computed below
    int c = 0;
#if defined(__SSE4_1__)
    // The next row's source lines are requested while this row is interpolated: on a full-size
    // frame (4.9 MB of cue pixels at 640 x 480) a window's taps mostly miss the caches, and a
    // window across a near-horizontal line touches two new lines per sample. A frame that fits
    // in the L2 cache (such as epic_window's 120 x 120) gains nothing from it and skips it.
    if (prefetch && r + 1 < g.rows) {
      const Eigen::Vector2d p1 = g.to_image(g.x_of_col(0), g.s_of_row(r + 1));
      prefetch_row(px, stride, w, static_cast<float>(p1.x()), static_cast<float>(p1.y()), ax, ay, g.cols, prefetch_step);
    }
    // Two passes over the row, four columns per register: first every column's image offset and
    // fractions (vector arithmetic only), then the taps. The taps' loads then wait on nothing but
    // these small arrays: in one pass each tap's loads sat at the end of the coordinate chain
    // and the taps could not overlap.
    {
      alignas(16) std::int32_t off[kMaxWindowWidth];
      alignas(16) float fxs[kMaxWindowWidth], fys[kMaxWindowWidth];
      const int groups = g.cols / 4 * 4;
      row_offsets(x0, y0, ax, ay, inside, xmax, ymax, w, groups, off, fxs, fys);
#if defined(EPICHEAD_WARP_AVX2)
      if (kHaveAvx2 && options_.allow_avx2) {
        row_taps_avx2(px, stride, off, fxs, fys, groups, pi + base, pr + base, pg + base, pt + base);
        c = groups;
      }
#endif
      row_taps(px, stride, off, fxs, fys, c, groups, pi + base, pr + base, pg + base, pt + base);
      c = groups;
    }
#endif
    for (; c < g.cols; ++c) {
      float x = x0 + static_cast<float>(c) * ax, y = y0 + static_cast<float>(c) * ay;
      if (!inside) {  // uniform per window: predicted perfectly
        x = std::clamp(x, 0.0f, xmax);
        y = std::clamp(y, 0.0f, ymax);
      }
      float v[4];
      tap(x, y, v);
      pi[base + c] = v[0];
      pr[base + c] = v[1];
      pg[base + c] = v[2];
      pt[base + c] = v[3];
    }
  }
  return true;
}

}  // namespace epichead::vision
