#pragma once
// Private to cues.cpp: the SSE4.1 kernels of the interval cues. The modal bin of up to 32 byte
// bins (intensity, chromaticity, texture) without a histogram, by prefix counts of equal lanes,
// and the masked sums of the modal pixels, with the tie rule and the summation order of the
// scalar histogram loop (CueHistograms::interval_histogram), so the same values.
#if defined(__SSE4_1__)
#include <array>
#include <cstdint>
#include <utility>

#include <immintrin.h>

#include "epichead/vision/cues.h"

namespace epichead::vision::cue_sse {

// Byte masks by lane: lanes_below(n) has lanes j < n set, lanes_from(s) lanes j >= s (0..16).
alignas(16) constexpr std::uint8_t kOnesThenZeros[32] = {
    0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
alignas(16) constexpr std::uint8_t kZerosThenOnes[32] = {
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0,
    0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF};
inline __m128i lanes_below(int n) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(kOnesThenZeros + 16 - n)); }
inline __m128i lanes_from(int s) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(kZerosThenOnes + 16 - s)); }

// Prefix counts of up to 16 byte bins: lane j = #{k <= j : b_k == b_j}. One compare of the
// register with itself shifted by s lanes adds the matches at distance s to every lane at once,
// so an interval of n pixels costs n - 1 compares instead of n histogram updates and clears.
// All three channels go through one loop, so they share its exit test.
template <int S>
inline void add_matches(__m128i b, __m128i& count) {
  count = _mm_sub_epi8(count, _mm_and_si128(_mm_cmpeq_epi8(b, _mm_slli_si128(b, S)), lanes_from(S)));
}
// Forced inline (as interval_span and interval_short below): GCC otherwise outlines part of it,
// and each interval then pays a call and its three counts through memory.
template <int... S>
[[gnu::always_inline]] inline void prefix_counts(const __m128i (&b)[3], int n, __m128i (&count)[3], std::integer_sequence<int, S...>) {
  for (__m128i& c : count) c = _mm_set1_epi8(1);
  // S + 1 = the shift; the fold stops at the first shift >= n (no lane has such a neighbour).
  (void)((n > S + 1 && (add_matches<S + 1>(b[0], count[0]), add_matches<S + 1>(b[1], count[1]),
                        add_matches<S + 1>(b[2], count[2]), true)) && ...);
}

// The mode of n <= 16 byte bins with the histogram loop's tie rule (the first bin to reach the
// top count wins, i.e. the first lane whose prefix count is the maximum). Returns the mask of
// the lanes in the modal bin and sets `top` to its count.
inline __m128i modal_lanes(__m128i b, __m128i count, __m128i valid, int& top) {
  count = _mm_and_si128(count, valid);
  // Key per lane: count in the high byte, 15 - lane in the low byte, so the largest key is the
  // first lane with the top count. PHMINPOSUW finds the smallest of eight complemented keys.
  const __m128i code = _mm_setr_epi8(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  const __m128i key = _mm_max_epu16(_mm_unpacklo_epi8(code, count), _mm_unpackhi_epi8(code, count));
  const int best = 0xFFFF & ~_mm_cvtsi128_si32(_mm_minpos_epu16(_mm_xor_si128(key, _mm_set1_epi8(-1))));
  top = best >> 8;
  const int lane = 15 - (best & 0xFF);
  const __m128i mode = _mm_shuffle_epi8(b, _mm_set1_epi8(static_cast<char>(lane)));
  return _mm_and_si128(_mm_cmpeq_epi8(b, mode), valid);
}

// Matches at distance 16 + S between hi lane j and lo lane j - S (lanes j >= S), as add_matches.
template <int S>
inline void add_cross(__m128i hi, __m128i lo, __m128i& count) {
  count = _mm_sub_epi8(count, _mm_and_si128(_mm_cmpeq_epi8(hi, _mm_slli_si128(lo, S)), lanes_from(S)));
}

// modal_lanes() over 32 lanes (lo all valid, hi where valid_hi): the first lane with the top count.
inline void modal_lanes2(__m128i lo, __m128i hi, __m128i count_lo, __m128i count_hi, __m128i valid_hi, int& top,
                         __m128i& hit_lo, __m128i& hit_hi) {
  count_hi = _mm_and_si128(count_hi, valid_hi);
  // Low byte 31 - lane: lo lanes 31..16, hi lanes 15..0 (the largest key is the first top lane).
  const __m128i code_lo = _mm_setr_epi8(31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19, 18, 17, 16);
  const __m128i code_hi = _mm_setr_epi8(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  const __m128i key = _mm_max_epu16(_mm_max_epu16(_mm_unpacklo_epi8(code_lo, count_lo), _mm_unpackhi_epi8(code_lo, count_lo)),
                                    _mm_max_epu16(_mm_unpacklo_epi8(code_hi, count_hi), _mm_unpackhi_epi8(code_hi, count_hi)));
  const int best = 0xFFFF & ~_mm_cvtsi128_si32(_mm_minpos_epu16(_mm_xor_si128(key, _mm_set1_epi8(-1))));
  top = best >> 8;
  const int lane = 31 - (best & 0xFF);
  const __m128i mode = _mm_shuffle_epi8(lane < 16 ? lo : hi, _mm_set1_epi8(static_cast<char>(lane & 15)));
  hit_lo = _mm_cmpeq_epi8(lo, mode);
  hit_hi = _mm_and_si128(_mm_cmpeq_epi8(hi, mode), valid_hi);
}

// Per pixel a 4-byte mask (I, R, G, T) = (hit_i, hit_c, hit_c, hit_t), four pixels per register.
inline void masks_by_pixel(__m128i hit_i, __m128i hit_c, __m128i hit_t, __m128i (&quads)[4]) {
  const __m128i ic_lo = _mm_unpacklo_epi8(hit_i, hit_c), ct_lo = _mm_unpacklo_epi8(hit_c, hit_t);
  const __m128i ic_hi = _mm_unpackhi_epi8(hit_i, hit_c), ct_hi = _mm_unpackhi_epi8(hit_c, hit_t);
  quads[0] = _mm_unpacklo_epi16(ic_lo, ct_lo);
  quads[1] = _mm_unpackhi_epi16(ic_lo, ct_lo);
  quads[2] = _mm_unpacklo_epi16(ic_hi, ct_hi);
  quads[3] = _mm_unpackhi_epi16(ic_hi, ct_hi);
}

// Adds the masked (I, R, G, T) of pixels p .. p + count - 1 (count <= 16) to sum in one add
// chain in pixel order, as interval_histogram() sums; lanes past count add +0. Four pixels of
// the four planes are transposed to four (I, R, G, T) vectors (the planes are padded, so the
// loads past the row's end stay inside them).
inline __m128 add_modal_sums(const std::array<const float*, kCueChannels>& planes, int p, int count,
                             const __m128i (&quads)[4], __m128 sum) {
  auto add = [&](__m128i mask8, __m128 v) {
    sum = _mm_add_ps(sum, _mm_and_ps(_mm_castsi128_ps(_mm_cvtepi8_epi32(mask8)), v));
  };
  for (int q = 0; 4 * q < count; ++q) {
    const int at = p + 4 * q;
    __m128 v0 = _mm_loadu_ps(planes[0] + at), v1 = _mm_loadu_ps(planes[1] + at);
    __m128 v2 = _mm_loadu_ps(planes[2] + at), v3 = _mm_loadu_ps(planes[3] + at);
    _MM_TRANSPOSE4_PS(v0, v1, v2, v3);  // v_k: pixel at + k
    add(quads[q], v0);
    add(_mm_srli_si128(quads[q], 4), v1);
    add(_mm_srli_si128(quads[q], 8), v2);
    add(_mm_srli_si128(quads[q], 12), v3);
  }
  return sum;
}


}  // namespace epichead::vision::cue_sse
#endif
