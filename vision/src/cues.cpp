#include "epichead/vision/cues.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#if defined(__SSE4_1__)
#include <immintrin.h>

#include "cue_modes_sse.h"
#endif

namespace epichead::vision {
#if defined(__SSE4_1__)
using namespace cue_sse;  // the kernels of cue_modes_sse.h
#endif
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

#if defined(__SSE4_1__)
namespace {
// exp_neg on four lanes: the same operations in the same order, so the same values.
inline __m128 exp_neg4(__m128 x) {
  x = _mm_max_ps(x, _mm_set1_ps(-80.0f));
  const __m128 t = _mm_mul_ps(x, _mm_set1_ps(1.44269504f));
  const __m128 fi = _mm_floor_ps(t);
  const __m128 f = _mm_sub_ps(t, fi);
  __m128 p = _mm_add_ps(_mm_set1_ps(0.00133335581f), _mm_mul_ps(f, _mm_set1_ps(0.000154035304f)));
  p = _mm_add_ps(_mm_set1_ps(0.00961812911f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(0.0555041087f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(0.240226507f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(0.693147181f), _mm_mul_ps(f, p));
  p = _mm_add_ps(_mm_set1_ps(1.0f), _mm_mul_ps(f, p));
  const __m128i bits = _mm_slli_epi32(_mm_add_epi32(_mm_cvttps_epi32(fi), _mm_set1_epi32(127)), 23);
  return _mm_mul_ps(p, _mm_castsi128_ps(bits));
}
}  // namespace
#endif

void cue_agreements(const IntervalCues* cues, int n, const CueReference& ref, bool colour, float* out) {
  int j = 0;
#if defined(__SSE4_1__)
  const __m128 mu0 = _mm_set1_ps(ref.mu[0]), mu1 = _mm_set1_ps(ref.mu[1]), mu2 = _mm_set1_ps(ref.mu[2]),
               mu3 = _mm_set1_ps(ref.mu[3]);
  const __m128 k0 = _mm_set1_ps(inv_two_var(ref.sigma[0])), k1 = _mm_set1_ps(inv_two_var(ref.sigma[1])),
               k2 = _mm_set1_ps(inv_two_var(ref.sigma[2])), k3 = _mm_set1_ps(inv_two_var(ref.sigma[3]));
  const __m128 sign = _mm_set1_ps(-0.0f);
  for (; j + 4 <= n; j += 4) {
    __m128 v0 = _mm_loadu_ps(cues[j].value.data()), v1 = _mm_loadu_ps(cues[j + 1].value.data());
    __m128 v2 = _mm_loadu_ps(cues[j + 2].value.data()), v3 = _mm_loadu_ps(cues[j + 3].value.data());
    _MM_TRANSPOSE4_PS(v0, v1, v2, v3);  // v_k: channel k of the four intervals
    const __m128 d0 = _mm_sub_ps(mu0, v0), d1 = _mm_sub_ps(mu1, v1), d2 = _mm_sub_ps(mu2, v2), d3 = _mm_sub_ps(mu3, v3);
    __m128 sum = _mm_add_ps(exp_neg4(_mm_mul_ps(_mm_mul_ps(_mm_xor_ps(d0, sign), d0), k0)),
                            exp_neg4(_mm_mul_ps(_mm_mul_ps(_mm_xor_ps(d3, sign), d3), k3)));
    if (colour) {
      const __m128 e = _mm_add_ps(_mm_mul_ps(_mm_mul_ps(d1, d1), k1), _mm_mul_ps(_mm_mul_ps(d2, d2), k2));
      sum = _mm_add_ps(sum, exp_neg4(_mm_xor_ps(e, sign)));
    }
    const __m128 valid = _mm_castsi128_ps(_mm_cmpgt_epi32(
        _mm_setr_epi32(cues[j].valid, cues[j + 1].valid, cues[j + 2].valid, cues[j + 3].valid), _mm_setzero_si128()));
    _mm_storeu_ps(out + j, _mm_and_ps(valid, sum));
  }
#endif
  for (; j < n; ++j) out[j] = cue_agreement(cues[j], ref, colour);
}

CueHistograms::CueHistograms(const CueOptions& options) : options_(options) {
  options_.intensity_bins = std::clamp(options_.intensity_bins, 2, 256);
  options_.chroma_bins = std::clamp(options_.chroma_bins, 2, 64);
  options_.texture_bins = std::clamp(options_.texture_bins, 2, 256);
  options_.texture_range = std::max(options_.texture_range, 1e-3f);
  options_.edge_margin_px = std::max(options_.edge_margin_px, 0);
  const std::size_t nc = static_cast<std::size_t>(options_.chroma_bins) * options_.chroma_bins;
  // Two interleaved copies per histogram (even and odd pixels), see interval().
  count_i_.assign(2 * static_cast<std::size_t>(options_.intensity_bins), 0);
  count_c_.assign(2 * nc, 0);
  count_t_.assign(2 * static_cast<std::size_t>(options_.texture_bins), 0);
  // Intensity and texture bins are at most 256 by the clamps above; the 2-D chroma bin fits a
  // byte up to 16 x 16.
  byte_bins_ = options_.chroma_bins <= 16;
}

void CueHistograms::prepare(const LineWindow& window) {
  const WindowGeometry& g = window.geometry();
  const int n = g.rows * g.cols;
  if (n > capacity_) {  // first window (or a larger one): warm-up only
    capacity_ = std::max(n, window.options().width_px * window.options().max_rows);
    if (!byte_bins_) bins_.resize(capacity_);
    // 32 pixels of padding: the short-interval paths load 16 or 32 pixels from an interval's start.
    const std::size_t padded = static_cast<std::size_t>(capacity_) + 32;
    if (byte_bins_) {
      bin8_i_.resize(padded);
      bin8_c_.resize(padded);
      bin8_t_.resize(padded);
    }
  }
  const float* I = window.plane(CueChannel::Intensity);
  const float* R = window.plane(CueChannel::ChromaR);
  const float* G = window.plane(CueChannel::ChromaG);
  const float* T = window.plane(CueChannel::Texture);
  const int ni = options_.intensity_bins, nc = options_.chroma_bins, nt = options_.texture_bins;
  const float si = ni / 256.0f, sc = nc / 256.0f, st = nt / options_.texture_range;
  // Clamped in float, then truncated: branch-free, so the loop vectorises.
  const float top_i = ni - 0.5f, top_c = nc - 0.5f, top_t = nt - 0.5f;
  std::uint64_t* __restrict bins = bins_.data();
  std::uint8_t* __restrict b8i = bin8_i_.data();
  std::uint8_t* __restrict b8c = bin8_c_.data();
  std::uint8_t* __restrict b8t = bin8_t_.data();
  const bool bytes = byte_bins_;
  auto clampf = [](float v, float hi) { v = v > 0.0f ? v : 0.0f; return v < hi ? v : hi; };
  int p = 0;
#if defined(__SSE4_1__)
  {
    // The same clamps (max/min against 0 and the top, NaN -> 0) and truncations as the scalar
    // loop, four pixels per register.
    const __m128 zero = _mm_setzero_ps(), vsi = _mm_set1_ps(si), vsc = _mm_set1_ps(sc), vst = _mm_set1_ps(st);
    const __m128 vti = _mm_set1_ps(top_i), vtc = _mm_set1_ps(top_c), vtt = _mm_set1_ps(top_t);
    const __m128i vnc = _mm_set1_epi32(nc);
    auto bin4 = [&](const float* x, __m128 scale, __m128 top) {
      return _mm_cvttps_epi32(_mm_min_ps(_mm_max_ps(_mm_mul_ps(_mm_loadu_ps(x), scale), zero), top));
    };
    auto bin_c4 = [&](int q) {
      return _mm_add_epi32(_mm_mullo_epi32(bin4(R + q, vsc, vtc), vnc), bin4(G + q, vsc, vtc));
    };
    if (bytes) {
      // Sixteen pixels per pass, each channel narrowed to one register of bytes (bins < 256,
      // so the saturating packs keep them) and stored at once.
      auto narrow = [](__m128i a, __m128i b, __m128i c, __m128i d) {
        return _mm_packus_epi16(_mm_packus_epi32(a, b), _mm_packus_epi32(c, d));
      };
      auto store16 = [](std::uint8_t* dst, __m128i v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(dst), v); };
      for (; p + 16 <= n; p += 16) {
        store16(b8i + p, narrow(bin4(I + p, vsi, vti), bin4(I + p + 4, vsi, vti), bin4(I + p + 8, vsi, vti),
                                bin4(I + p + 12, vsi, vti)));
        store16(b8c + p, narrow(bin_c4(p), bin_c4(p + 4), bin_c4(p + 8), bin_c4(p + 12)));
        store16(b8t + p, narrow(bin4(T + p, vst, vtt), bin4(T + p + 4, vst, vtt), bin4(T + p + 8, vst, vtt),
                                bin4(T + p + 12, vst, vtt)));
      }
    } else {
      for (; p + 4 <= n; p += 4) {
        const __m128i bi = bin4(I + p, vsi, vti), bt = bin4(T + p, vst, vtt), bc = bin_c4(p);
        const __m128i lo = _mm_or_si128(bi, _mm_slli_epi32(bc, 16));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(bins + p), _mm_unpacklo_epi32(lo, bt));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(bins + p + 2), _mm_unpackhi_epi32(lo, bt));
      }
    }
  }
#endif
  for (; p < n; ++p) {
    const auto bi = static_cast<std::uint32_t>(static_cast<int>(clampf(I[p] * si, top_i)));
    const auto bt = static_cast<std::uint32_t>(static_cast<int>(clampf(T[p] * st, top_t)));
    const auto bc = static_cast<std::uint32_t>(static_cast<int>(clampf(R[p] * sc, top_c)) * nc +
                                               static_cast<int>(clampf(G[p] * sc, top_c)));
    if (bytes) {
      b8i[p] = static_cast<std::uint8_t>(bi);
      b8c[p] = static_cast<std::uint8_t>(bc);
      b8t[p] = static_cast<std::uint8_t>(bt);
    } else {
      bins[p] = (static_cast<std::uint64_t>(bt) << 32) | (bc << 16) | bi;
    }
  }
  planes_ = {I, R, G, T};
}

IntervalCues CueHistograms::interval(const LineWindow& window, int row, int col_begin, int col_end) {
  IntervalCues out;
  const WindowGeometry& g = window.geometry();
  col_begin = std::max(col_begin, 0);
  col_end = std::min(col_end, g.cols);
  if (row < 0 || row >= g.rows || col_end <= col_begin) return out;
  const int p0 = row * g.cols + col_begin, p1 = row * g.cols + col_end;
  return interval_span(p0, p1);
}

[[gnu::always_inline]] inline IntervalCues CueHistograms::interval_span(int p0, int p1) {
#if defined(__SSE4_1__)
  if (byte_bins_ && p1 - p0 <= 16) return interval_short(p0, p1 - p0);
  if (byte_bins_ && p1 - p0 <= 32) return interval_short2(p0, p1 - p0);
#endif
  return interval_histogram(p0, p1);
}

IntervalCues CueHistograms::interval_histogram(int p0, int p1) {
  IntervalCues out;
  // Pass 1: counts only, tracking each mode (the first bin to reach the top count wins ties).
  // Keeping sums out of this loop shortens its store-to-load chains (neighbouring pixels mostly
  // share a bin); two copies of each histogram, one for even and one for odd pixels (element
  // 2 b and 2 b + 1), halve them again: a pixel's count is the sum of both copies, and the
  // increment of one copy no longer waits for the previous pixel's store.
  // The three bins of a pixel packed as in bins_, read from the byte planes when those are used.
  const std::uint64_t* const words = bins_.data();
  const std::uint8_t* const b8i = bin8_i_.data();
  const std::uint8_t* const b8c = bin8_c_.data();
  const std::uint8_t* const b8t = bin8_t_.data();
  const bool bytes = byte_bins_;
  auto word = [&](int p) -> std::uint64_t {
    if (!bytes) return words[p];
    return b8i[p] | (std::uint64_t{b8c[p]} << 16) | (std::uint64_t{b8t[p]} << 32);
  };
  int best_i = static_cast<int>(word(p0) & 0xFFFF), best_c = static_cast<int>((word(p0) >> 16) & 0xFFFF),
      best_t = static_cast<int>(word(p0) >> 32);
  int top_i = 0, top_c = 0, top_t = 0;
  std::uint16_t* const hist_i = count_i_.data();
  std::uint16_t* const hist_c = count_c_.data();
  std::uint16_t* const hist_t = count_t_.data();
  auto step = [&](std::uint64_t q, int k) {
    const int bi = static_cast<int>(q & 0xFFFF), bc = static_cast<int>((q >> 16) & 0xFFFF), bt = static_cast<int>(q >> 32);
    std::uint16_t* const hi = hist_i + 2 * bi;
    std::uint16_t* const hc = hist_c + 2 * bc;
    std::uint16_t* const ht = hist_t + 2 * bt;
    const int ci = ++hi[k] + hi[k ^ 1], cc = ++hc[k] + hc[k ^ 1], ct = ++ht[k] + ht[k ^ 1];
    best_i = ci > top_i ? bi : best_i;
    top_i = ci > top_i ? ci : top_i;
    best_c = cc > top_c ? bc : best_c;
    top_c = cc > top_c ? cc : top_c;
    best_t = ct > top_t ? bt : best_t;
    top_t = ct > top_t ? ct : top_t;
  };
  int p = p0;
  for (; p + 2 <= p1; p += 2) {
    step(word(p), 0);
    step(word(p + 1), 1);
  }
  if (p < p1) step(word(p), 0);
  // Pass 2: clear the touched bins and sum the samples of each modal bin (branch-free), so the
  // mode is refined to the mean of its bin (finer than the bin width).
  std::uint16_t* __restrict ci_ = count_i_.data();
  std::uint16_t* __restrict cc_ = count_c_.data();
  std::uint16_t* __restrict ct_ = count_t_.data();
  const float* const I = planes_[0];
  const float* const R = planes_[1];
  const float* const G = planes_[2];
  const float* const T = planes_[3];
  auto clear2 = [](std::uint16_t* h) { const std::uint32_t z = 0; std::memcpy(h, &z, sizeof z); };
#if defined(__SSE4_1__)
  // Lanes (I, R, G, T) against the modal bins (intensity, chroma, chroma, texture).
  const __m128i best = _mm_setr_epi32(best_i, best_c, best_c, best_t);
  auto masked = [&](int p) {
    const std::uint64_t q = word(p);
    clear2(ci_ + 2 * (q & 0xFFFF));
    clear2(cc_ + 2 * ((q >> 16) & 0xFFFF));
    clear2(ct_ + 2 * (q >> 32));
    const __m128i b = _mm_shuffle_epi32(_mm_cvtepu16_epi32(_mm_cvtsi64_si128(static_cast<long long>(q))), 0x94);
    const __m128 hit = _mm_castsi128_ps(_mm_cmpeq_epi32(b, best));
    return _mm_and_ps(hit, _mm_setr_ps(I[p], R[p], G[p], T[p]));
  };
  // One add chain in pixel order, so the sums are those of the scalar loop.
  __m128 sum = _mm_setzero_ps();
  for (p = p0; p < p1; ++p) sum = _mm_add_ps(sum, masked(p));
  alignas(16) float s4[4];
  _mm_store_ps(s4, sum);
  const float si = s4[0], sr = s4[1], sg = s4[2], st = s4[3];
#else
  float si = 0, sr = 0, sg = 0, st = 0;
  for (int p = p0; p < p1; ++p) {
    const std::uint64_t q = word(p);
    const int bi = static_cast<int>(q & 0xFFFF), bc = static_cast<int>((q >> 16) & 0xFFFF), bt = static_cast<int>(q >> 32);
    clear2(ci_ + 2 * bi);
    clear2(cc_ + 2 * bc);
    clear2(ct_ + 2 * bt);
    si += bi == best_i ? I[p] : 0.0f;
    sr += bc == best_c ? R[p] : 0.0f;
    sg += bc == best_c ? G[p] : 0.0f;
    st += bt == best_t ? T[p] : 0.0f;
  }
#endif
  out.value[0] = si / static_cast<float>(top_i);
  out.value[1] = sr / static_cast<float>(top_c);
  out.value[2] = sg / static_cast<float>(top_c);
  out.value[3] = st / static_cast<float>(top_t);
  out.valid = true;
  return out;
}

#if defined(__SSE4_1__)
[[gnu::always_inline]] inline IntervalCues CueHistograms::interval_short(int p0, int n) const {
  // The same modes, tie rule and modal-bin sums as interval_histogram(), for n <= 16 pixels.
  auto load = [p0](const std::vector<std::uint8_t>& plane) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(plane.data() + p0));
  };
  const __m128i b[3] = {load(bin8_i_), load(bin8_c_), load(bin8_t_)};
  __m128i count[3];
  prefix_counts(b, n, count, std::make_integer_sequence<int, 15>{});
  const __m128i valid = lanes_below(n);
  int top_i = 0, top_c = 0, top_t = 0;
  const __m128i hit_i = modal_lanes(b[0], count[0], valid, top_i);
  const __m128i hit_c = modal_lanes(b[1], count[1], valid, top_c);
  const __m128i hit_t = modal_lanes(b[2], count[2], valid, top_t);
  __m128i quads[4];
  masks_by_pixel(hit_i, hit_c, hit_t, quads);
  const __m128 sum = add_modal_sums(planes_, p0, n, quads, _mm_setzero_ps());
  alignas(16) float s4[4];
  _mm_store_ps(s4, sum);
  IntervalCues out;
  out.value[0] = s4[0] / static_cast<float>(top_i);
  out.value[1] = s4[1] / static_cast<float>(top_c);
  out.value[2] = s4[2] / static_cast<float>(top_c);
  out.value[3] = s4[3] / static_cast<float>(top_t);
  out.valid = true;
  return out;
}

IntervalCues CueHistograms::interval_short2(int p0, int n) const {
  // As interval_short() for 16 < n <= 32 pixels in two registers per channel, lo (pixels 0..15)
  // and hi (16..n-1). lo's prefix counts are its own. A hi lane at distance s from an earlier
  // pixel finds it, for s <= 15, in the register made of lo's last s lanes and hi's first 16 - s
  // (PALIGNR), and for s >= 16 in lo shifted by s - 16.
  auto load = [p0](const std::vector<std::uint8_t>& plane, int at) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(plane.data() + p0 + at));
  };
  const __m128i lo[3] = {load(bin8_i_, 0), load(bin8_c_, 0), load(bin8_t_, 0)};
  const __m128i hi[3] = {load(bin8_i_, 16), load(bin8_c_, 16), load(bin8_t_, 16)};
  __m128i count_lo[3], count_hi[3];
  prefix_counts(lo, 16, count_lo, std::make_integer_sequence<int, 15>{});
  for (__m128i& c : count_hi) c = _mm_set1_epi8(1);
  [&]<int... S>(std::integer_sequence<int, S...>) {
    // s = S + 1 = 1..15: every hi lane has its partner at distance s.
    ((count_hi[0] = _mm_sub_epi8(count_hi[0], _mm_cmpeq_epi8(hi[0], _mm_alignr_epi8(hi[0], lo[0], 15 - S))),
      count_hi[1] = _mm_sub_epi8(count_hi[1], _mm_cmpeq_epi8(hi[1], _mm_alignr_epi8(hi[1], lo[1], 15 - S))),
      count_hi[2] = _mm_sub_epi8(count_hi[2], _mm_cmpeq_epi8(hi[2], _mm_alignr_epi8(hi[2], lo[2], 15 - S)))), ...);
  }(std::make_integer_sequence<int, 15>{});
  for (int k = 0; k < 3; ++k) count_hi[k] = _mm_sub_epi8(count_hi[k], _mm_cmpeq_epi8(hi[k], lo[k]));  // s = 16
  // s = 17 + S: hi lane j pairs with lo lane j - 1 - S (lanes j >= 1 + S); stops at s >= n.
  [&]<int... S>(std::integer_sequence<int, S...>) {
    (void)((n > S + 17 && (add_cross<S + 1>(hi[0], lo[0], count_hi[0]), add_cross<S + 1>(hi[1], lo[1], count_hi[1]),
                           add_cross<S + 1>(hi[2], lo[2], count_hi[2]), true)) && ...);
  }(std::make_integer_sequence<int, 15>{});
  const __m128i valid_hi = lanes_below(n - 16);
  int top[3];
  __m128i hit_lo[3], hit_hi[3];
  for (int k = 0; k < 3; ++k) modal_lanes2(lo[k], hi[k], count_lo[k], count_hi[k], valid_hi, top[k], hit_lo[k], hit_hi[k]);
  // The sums in pixel order, as in interval_short(), over both registers' pixels.
  __m128i quads_lo[4], quads_hi[4];
  masks_by_pixel(hit_lo[0], hit_lo[1], hit_lo[2], quads_lo);
  masks_by_pixel(hit_hi[0], hit_hi[1], hit_hi[2], quads_hi);
  const __m128 sum = add_modal_sums(planes_, p0 + 16, n - 16, quads_hi, add_modal_sums(planes_, p0, 16, quads_lo, _mm_setzero_ps()));
  alignas(16) float s4[4];
  _mm_store_ps(s4, sum);
  IntervalCues out;
  out.value[0] = s4[0] / static_cast<float>(top[0]);
  out.value[1] = s4[1] / static_cast<float>(top[1]);
  out.value[2] = s4[2] / static_cast<float>(top[1]);
  out.value[3] = s4[3] / static_cast<float>(top[2]);
  out.valid = true;
  return out;
}
#endif

void CueHistograms::intervals(const LineWindow& window, EdgelSet& edgels, std::vector<IntervalCues>& out,
                              bool left_of_edgels, bool right_of_edgels) {
  const WindowGeometry& g = window.geometry();
  const int margin = options_.edge_margin_px;
  // Row r holds edgels [row_begin[r], row_begin[r + 1]) and one interval more; the caller
  // reserved the capacity, so this resize does not allocate.
  out.resize(edgels.edgels.size() + static_cast<std::size_t>(std::max(edgels.rows, 0)));
  IntervalCues* next = out.data();
  // Columns [lo, hi) of row r: empty spans are invalid, as in interval().
  auto span = [&](int r, int lo, int hi) {
    lo = std::max(lo, 0);
    hi = std::min(hi, g.cols);
    return hi > lo && r < g.rows ? interval_span(r * g.cols + lo, r * g.cols + hi) : IntervalCues{};
  };
  for (int r = 0; r < edgels.rows; ++r) {
    int lo = 0;
    const int b = edgels.row_begin[r], e_end = edgels.row_begin[r + 1];
    for (int e = b; e < e_end; ++e) {
      Edgel& edgel = edgels.edgels[e];
      const int c = static_cast<int>(edgel.col + 0.5f);  // col >= 2: truncation rounds
      edgel.left_interval = static_cast<int>(next - out.data());
      // Interval e is left of edgel e and right of edgel e - 1: skip it when neither side is used.
      const bool needed = left_of_edgels || (right_of_edgels && e > b);
      *next++ = needed ? span(r, lo, c - margin) : IntervalCues{};
      lo = c + margin + 1;
    }
    *next++ = right_of_edgels && e_end > b ? span(r, lo, g.cols) : IntervalCues{};
  }
  out.resize(static_cast<std::size_t>(next - out.data()));
}

}  // namespace epichead::vision
