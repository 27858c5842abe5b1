#include "epichead/vision/cues.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace epichead::vision {
namespace {

// exp(x) for x <= 0 without a libm call (the likelihood evaluates three per interval): 2^t with
// t = x log2(e) split into integer and fraction, 2^f by its degree-6 Taylor polynomial
// (relative error < 2e-5, far below what a likelihood needs).
inline float exp_neg(float x) {
  x = std::max(x, -80.0f);
  const float t = x * 1.44269504f;
  const float fi = std::floor(t);
  const float f = t - fi;
  const float p = 1.0f + f * (0.693147181f + f * (0.240226507f + f * (0.0555041087f +
                  f * (0.00961812911f + f * (0.00133335581f + f * 0.000154035304f)))));
  const int bits = (static_cast<int>(fi) + 127) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

inline float inv_two_var(float sigma) {
  sigma = std::max(sigma, 1e-3f);
  return 0.5f / (sigma * sigma);
}

inline int bin_of(float v, float scale, int bins) {
  // v >= 0 for every channel; the clamp also maps rounding at the top into the last bin.
  return std::clamp(static_cast<int>(v * scale), 0, bins - 1);
}

}  // namespace

float cue_agreement(const IntervalCues& cues, const CueReference& ref, bool colour) {
  if (!cues.valid) return 0.0f;
  const auto& v = cues.value;
  const float d0 = ref.mu[0] - v[0], d1 = ref.mu[1] - v[1], d2 = ref.mu[2] - v[2], d3 = ref.mu[3] - v[3];
  float sum = exp_neg(-d0 * d0 * inv_two_var(ref.sigma[0])) + exp_neg(-d3 * d3 * inv_two_var(ref.sigma[3]));
  // Colour is one cue with a 2-D value: one Gaussian with a diagonal covariance.
  if (colour) sum += exp_neg(-(d1 * d1 * inv_two_var(ref.sigma[1]) + d2 * d2 * inv_two_var(ref.sigma[2])));
  return sum;
}

CueHistograms::CueHistograms(const CueOptions& options) : options_(options) {
  options_.intensity_bins = std::clamp(options_.intensity_bins, 2, 256);
  options_.chroma_bins = std::clamp(options_.chroma_bins, 2, 64);
  options_.texture_bins = std::clamp(options_.texture_bins, 2, 256);
  options_.texture_range = std::max(options_.texture_range, 1e-3f);
  options_.edge_margin_px = std::max(options_.edge_margin_px, 0);
  const std::size_t nc = static_cast<std::size_t>(options_.chroma_bins) * options_.chroma_bins;
  count_i_.assign(options_.intensity_bins, 0);
  count_c_.assign(nc, 0);
  count_t_.assign(options_.texture_bins, 0);
}

void CueHistograms::prepare(const LineWindow& window) {
  const WindowGeometry& g = window.geometry();
  const int n = g.rows * g.cols;
  if (n > capacity_) {  // first window (or a larger one): warm-up only
    capacity_ = std::max(n, window.options().width_px * window.options().max_rows);
    bin_i_.resize(capacity_);
    bin_t_.resize(capacity_);
    bin_c_.resize(capacity_);
  }
  const float* I = window.plane(CueChannel::Intensity);
  const float* R = window.plane(CueChannel::ChromaR);
  const float* G = window.plane(CueChannel::ChromaG);
  const float* T = window.plane(CueChannel::Texture);
  const int ni = options_.intensity_bins, nc = options_.chroma_bins, nt = options_.texture_bins;
  const float si = ni / 256.0f, sc = nc / 256.0f, st = nt / options_.texture_range;
  // Clamped in float, then truncated: branch-free, so the loop vectorises.
  const float top_i = ni - 0.5f, top_c = nc - 0.5f, top_t = nt - 0.5f;
  std::uint16_t* __restrict bi = bin_i_.data();
  std::uint16_t* __restrict bt = bin_t_.data();
  std::uint16_t* __restrict bc = bin_c_.data();
  auto clampf = [](float v, float hi) { v = v > 0.0f ? v : 0.0f; return v < hi ? v : hi; };
  for (int p = 0; p < n; ++p) {
    bi[p] = static_cast<std::uint16_t>(static_cast<int>(clampf(I[p] * si, top_i)));
    bt[p] = static_cast<std::uint16_t>(static_cast<int>(clampf(T[p] * st, top_t)));
    bc[p] = static_cast<std::uint16_t>(static_cast<int>(clampf(R[p] * sc, top_c)) * nc +
                                       static_cast<int>(clampf(G[p] * sc, top_c)));
  }
}

IntervalCues CueHistograms::interval(const LineWindow& window, int row, int col_begin, int col_end) {
  IntervalCues out;
  const WindowGeometry& g = window.geometry();
  col_begin = std::max(col_begin, 0);
  col_end = std::min(col_end, g.cols);
  if (row < 0 || row >= g.rows || col_end <= col_begin) return out;
  const int p0 = row * g.cols + col_begin, p1 = row * g.cols + col_end;
  const float* I = window.plane(CueChannel::Intensity);
  const float* R = window.plane(CueChannel::ChromaR);
  const float* G = window.plane(CueChannel::ChromaG);
  const float* T = window.plane(CueChannel::Texture);
  // Pass 1: counts only, tracking each mode (the first bin to reach the top count wins ties).
  // Keeping sums out of this loop shortens its store-to-load chains (neighbouring pixels mostly
  // share a bin).
  int best_i = bin_i_[p0], best_c = bin_c_[p0], best_t = bin_t_[p0];
  int top_i = 0, top_c = 0, top_t = 0;
  for (int p = p0; p < p1; ++p) {
    const int bi = bin_i_[p], bc = bin_c_[p], bt = bin_t_[p];
    const int ci = ++count_i_[bi], cc = ++count_c_[bc], ct = ++count_t_[bt];
    best_i = ci > top_i ? bi : best_i;
    top_i = ci > top_i ? ci : top_i;
    best_c = cc > top_c ? bc : best_c;
    top_c = cc > top_c ? cc : top_c;
    best_t = ct > top_t ? bt : best_t;
    top_t = ct > top_t ? ct : top_t;
  }
  // Pass 2: clear the touched bins and sum the samples of each modal bin (branch-free), so the
  // mode is refined to the mean of its bin (finer than the bin width).
  float si = 0, sr = 0, sg = 0, st = 0;
  for (int p = p0; p < p1; ++p) {
    const int bi = bin_i_[p], bc = bin_c_[p], bt = bin_t_[p];
    count_i_[bi] = 0;
    count_c_[bc] = 0;
    count_t_[bt] = 0;
    si += bi == best_i ? I[p] : 0.0f;
    sr += bc == best_c ? R[p] : 0.0f;
    sg += bc == best_c ? G[p] : 0.0f;
    st += bt == best_t ? T[p] : 0.0f;
  }
  out.value[0] = si / static_cast<float>(top_i);
  out.value[1] = sr / static_cast<float>(top_c);
  out.value[2] = sg / static_cast<float>(top_c);
  out.value[3] = st / static_cast<float>(top_t);
  out.valid = true;
  return out;
}

void CueHistograms::intervals(const LineWindow& window, EdgelSet& edgels, std::vector<IntervalCues>& out,
                              bool left_of_edgels, bool right_of_edgels) {
  out.clear();
  const WindowGeometry& g = window.geometry();
  const int margin = options_.edge_margin_px;
  for (int r = 0; r < edgels.rows; ++r) {
    int lo = 0;
    const int b = edgels.row_begin[r], e_end = edgels.row_begin[r + 1];
    for (int e = b; e < e_end; ++e) {
      Edgel& edgel = edgels.edgels[e];
      const int c = static_cast<int>(edgel.col + 0.5f);  // col >= 2: truncation rounds
      edgel.left_interval = static_cast<int>(out.size());
      // Interval e is left of edgel e and right of edgel e - 1: skip it when neither side is used.
      const bool needed = left_of_edgels || (right_of_edgels && e > b);
      out.push_back(needed ? interval(window, r, lo, c - margin) : IntervalCues{});
      lo = c + margin + 1;
    }
    out.push_back(right_of_edgels && e_end > b ? interval(window, r, lo, g.cols) : IntervalCues{});
  }
}

}  // namespace epichead::vision
