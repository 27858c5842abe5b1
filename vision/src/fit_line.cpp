#include "epichead/vision/fit_line.h"

#include "ransac_common.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace epichead::vision {

float WindowLine::distance(float x_px, float s_px) const {
  return std::fabs(x_px - m * s_px - c) / std::sqrt(1.0f + m * m);
}

WindowLine fit_line_tls(const float* x_px, const float* s_px, const int* idx, int n) {
  WindowLine line;
  if (n < 1) return line;
  double mx = 0, ms = 0;
  for (int k = 0; k < n; ++k) { mx += x_px[idx[k]]; ms += s_px[idx[k]]; }
  mx /= n;
  ms /= n;
  double sxx = 0, sss = 0, sxs = 0;
  for (int k = 0; k < n; ++k) {
    const double dx = x_px[idx[k]] - mx, ds = s_px[idx[k]] - ms;
    sxx += dx * dx;
    sss += ds * ds;
    sxs += dx * ds;
  }
  // Direction of largest spread in (s, x): the principal axis of the 2x2 scatter is at
  // theta = atan2(b, a) / 2 from the s axis, a = sss - sxx, b = 2 sxs, and its slope is
  // tan(theta) = b / (r + a), r = |(a, b)| (the half-angle formula: no atan2, cos or sin, which
  // were most of the refinement's cost). A window line is near-vertical (along s), so a > 0 and
  // r + a is far from 0; a line across the window (r + a ~ 0, slope beyond 1e6) gets m = 0.
  const double a = sss - sxx, b = 2.0 * sxs;
  const double r = std::sqrt(a * a + b * b);
  const double m_axis = r + a > 0 ? b / (r + a) : 0.0;
  const double m = std::fabs(m_axis) < 1e6 ? m_axis : 0.0;
  line.m = static_cast<float>(m);
  line.c = static_cast<float>(mx - m * ms);
  return line;
}

LineRansac::LineRansac(const RansacOptions& options, int max_points)
    : options_(options), max_points_(std::max(max_points, 2)) {
  hypotheses_.reserve(32);
  candidates_.reserve(32);
  inliers_.reserve(static_cast<std::size_t>(max_points_) * 32);
  scratch_.assign(max_points_, 0);  // collect_inliers writes indices into it (count apart)
  claimed_.assign(max_points_, 0);
}

int LineRansac::count_support(const WindowLine& line, const float* x, const float* s, int n) const {
  // |x - m s - c| <= d sqrt(1 + m^2): no division or root per point, and vectorisable.
  const float tol = options_.inlier_distance_px * std::sqrt(1.0f + line.m * line.m);
  int support = 0;
  for (int i = 0; i < n; ++i) support += std::fabs(x[i] - line.m * s[i] - line.c) <= tol;
  return support;
}

bool LineRansac::same_line(const WindowLine& a, const WindowLine& b) const {
  const float d0 = std::fabs(a.x_at(s_begin_) - b.x_at(s_begin_));
  const float d1 = std::fabs(a.x_at(s_end_) - b.x_at(s_end_));
  return std::max(d0, d1) < options_.min_separation_px;
}

int LineRansac::fit(const float* x, const float* s, int n, float s_begin, float s_end) {
  candidates_.clear();
  inliers_.clear();
  hypotheses_.clear();
  iterations_ = 0;
  n = std::min(n, max_points_);
  s_begin_ = s_begin;
  s_end_ = s_end;
  const int max_keep = std::max(1, options_.max_candidates);
  if (n < std::max(2, options_.min_support)) return 0;
  ransac::Xorshift32 rng(options_.seed);  // a local: its state stays in a register
  const double log_fail = ransac::log_failure(options_.probability);
  const float keep = std::clamp(options_.keep_ratio, 0.0f, 1.0f);
  // Eq. 4 with w = keep * inlier ratio when several candidates are wanted (see header).
  const double w_factor = max_keep > 1 ? keep : 1.0f;
  auto same = [this](const Hypothesis& a, const Hypothesis& b) { return same_line(a.line, b.line); };
  int best = 0;
  int budget = options_.max_iterations;
  int iterations = 0;  // a local, like the generator
  for (; iterations < budget; ++iterations) {
    const int i = rng.below(n);
    int j = rng.below(n - 1);
    if (j >= i) ++j;
    const float ds = s[j] - s[i];
    if (std::fabs(ds) < 1e-3f) continue;  // same row: no near-vertical line through both
    WindowLine line;
    line.m = (x[j] - x[i]) / ds;
    line.c = x[i] - line.m * s[i];
    const int support = count_support(line, x, s, n);
    if (support < options_.min_support) continue;
    if (support > best) {
      best = support;
      const double w = w_factor * static_cast<double>(best) / n;
      budget = std::max(1, ransac::iterations_needed(log_fail, w, 2, options_.max_iterations));
    }
    if (support < keep * best) continue;
    ransac::pool_hypothesis(hypotheses_, Hypothesis{line, support}, same);  // strongest per distinct line
  }
  iterations_ = iterations;
  // Refine each surviving hypothesis: inliers -> TLS -> inliers -> TLS -> final inliers.
  ransac::sort_strongest_first(hypotheses_);
  const float tol = options_.inlier_distance_px;
  std::fill(claimed_.begin(), claimed_.begin() + n, 0);
  // The points within tol of a line into scratch_: WindowLine::distance with its root taken
  // once per line instead of once per point (the same operations, so the same decisions), four
  // points per SSE pass and their indices written from the compare mask. Returns their count.
  auto collect_inliers = [&](const WindowLine& line) {
    const float norm = std::sqrt(1.0f + line.m * line.m);
    int* out = scratch_.data();
    int count = 0, k = 0;
#if defined(__SSE2__)
    const __m128 vm = _mm_set1_ps(line.m), vc = _mm_set1_ps(line.c), vnorm = _mm_set1_ps(norm), vtol = _mm_set1_ps(tol);
    const __m128 sign = _mm_set1_ps(-0.0f);
    for (; k + 4 <= n; k += 4) {
      const __m128 r = _mm_sub_ps(_mm_sub_ps(_mm_loadu_ps(x + k), _mm_mul_ps(vm, _mm_loadu_ps(s + k))), vc);
      const __m128 d = _mm_div_ps(_mm_andnot_ps(sign, r), vnorm);
      for (int bits = _mm_movemask_ps(_mm_cmple_ps(d, vtol)); bits != 0; bits &= bits - 1) out[count++] = k + __builtin_ctz(bits);
    }
#endif
    for (; k < n; ++k)
      if (std::fabs(x[k] - line.m * s[k] - line.c) / norm <= tol) out[count++] = k;
    return count;
  };
  for (const Hypothesis& h : hypotheses_) {
    if (h.support < keep * best) continue;
    WindowLine line = h.line;
    for (int pass = 0; pass < 2; ++pass) {
      const int found = collect_inliers(line);
      if (found < 2) break;
      line = fit_line_tls(x, s, scratch_.data(), found);
    }
    const int support = collect_inliers(line);
    if (support < options_.min_support) continue;
    // Refinement can pull two hypotheses onto one line: keep the first (stronger) one.
    bool duplicate = false;
    for (const LineFit& f : candidates_) duplicate = duplicate || same_line(f.line, line);
    if (duplicate) continue;
    // A line that lives on points already claimed by stronger candidates is no line of its
    // own: two close parallel edges make diagonals that cross both within the inlier band.
    // Hypotheses come strongest first, so this is decided in support order.
    if (!ransac::claim_own_points(scratch_.data(), support, claimed_, std::max<double>(keep * best, options_.min_support)))
      continue;
    LineFit fit;
    fit.line = line;
    fit.support = support;
    fit.inlier_begin = static_cast<int>(inliers_.size());
    inliers_.insert(inliers_.end(), scratch_.begin(), scratch_.begin() + support);
    candidates_.push_back(fit);
  }
  ransac::sort_and_cut(candidates_, max_keep, keep);
  return static_cast<int>(candidates_.size());
}

}  // namespace epichead::vision
