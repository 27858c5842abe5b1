#pragma once
// Cues (EPIC step 3b): intensity, colour (chromaticity r, g) and texture. The cue value of an
// interval between two edgels is the mode of the cue's histogram over the interval (the paper's
// choice: robust to the blurred pixels at the interval ends and cheaper than a median), refined
// to the mean of the samples in the modal bin. An interval is compared with a reference mean and
// deviation by C = exp(-(mu - c)^2 / (2 sigma^2)) (Eq. 1 read with sigma^2: dimensionless).
#include <array>
#include <cstdint>
#include <vector>

#include "epichead/vision/edgels.h"
#include "epichead/vision/line_window.h"

namespace epichead::vision {

// The cue value of one interval, per CueChannel; valid = false for an empty interval.
struct IntervalCues {
  std::array<float, kCueChannels> value{};
  bool valid = false;
};

// Reference of one side of one feature: mean and deviation per CueChannel.
struct CueReference {
  std::array<float, kCueChannels> mu{};
  std::array<float, kCueChannels> sigma{};
};

struct CueOptions {
  // Histogram bins: intensity over 0..256, chromaticity per axis over 0..256 (a 2-D histogram),
  // texture over 0..texture_range (larger values fall in the last bin).
  int intensity_bins = 32;
  int chroma_bins = 16;
  int texture_bins = 32;
  float texture_range = 64.0f;
  // Pixels either side of an edgel left out of both intervals: the blurred transition belongs
  // to neither surface.
  int edge_margin_px = 1;
  // Floors on sigma per channel (intensity, chroma r, chroma g, texture), so that a perfectly
  // uniform surface does not make C a delta: about the camera noise plus half a bin.
  std::array<float, kCueChannels> sigma_floor{4.0f, 4.0f, 4.0f, 2.0f};
};

// Number of cues the likelihood sums over: 3 with colour, 2 without.
inline int cue_count(bool colour) { return colour ? 3 : 2; }

// Sum over cues of C_i (intensity, colour as one 2-D cue, texture), in [0, cue_count].
// An invalid interval contributes 0: no evidence for the edgel.
float cue_agreement(const IntervalCues& cues, const CueReference& ref, bool colour);
// out[j] = cue_agreement(cues[j], ref, colour) for j < n (the same values, four at a time).
void cue_agreements(const IntervalCues* cues, int n, const CueReference& ref, bool colour, float* out);

// Per-window histogram machinery: bins every pixel once, then takes interval modes.
class CueHistograms {
 public:
  explicit CueHistograms(const CueOptions& options = {});
  const CueOptions& options() const { return options_; }
  // Bins all pixels of `window` (call once per window before interval()).
  void prepare(const LineWindow& window);
  // Mode of each cue over columns [col_begin, col_end) of `row`; invalid when empty.
  IntervalCues interval(const LineWindow& window, int row, int col_begin, int col_end);
  // The intervals of every row split at the edgels (edge_margin_px left out around each):
  // row r with m edgels gives m + 1 intervals; edgel e's left interval is e + r, so
  // `edgels.edgels[e].left_interval` is set here. `out` has capacity reserved by the caller.
  // Only intervals on the used side(s) of the edgels are computed (the object side: the other
  // side's weight is 0); the rest are left invalid.
  void intervals(const LineWindow& window, EdgelSet& edgels, std::vector<IntervalCues>& out,
                 bool left_of_edgels = true, bool right_of_edgels = true);

 private:
  CueOptions options_;
  int capacity_ = 0;
  // Per pixel, the three bins packed in one word (one load per pixel in the interval loops):
  // bits 0..15 intensity, 16..31 the 2-D chroma bin, 32..47 texture. Used when a bin index
  // does not fit a byte (chroma_bins > 16); else the byte planes below hold the bins.
  std::vector<std::uint64_t> bins_;
  // The bins as one byte per pixel and channel (intensity, 2-D chroma, texture), padded by
  // 32 bytes: an interval of up to 16 pixels is one register per channel and its mode is found
  // without a histogram (interval_short), up to 32 two registers (interval_short2); longer
  // ones run the histogram loop over these bytes.
  bool byte_bins_ = false;
  std::vector<std::uint8_t> bin8_i_, bin8_c_, bin8_t_;
  // The planes of the window given to prepare() (I, R, G, T): the modal-bin sums read them.
  std::array<const float*, kCueChannels> planes_{};
  // Histogram counts, all zero between calls (cleared by revisiting the interval's pixels); two
  // interleaved copies (element 2 b for even pixels, 2 b + 1 for odd) break the counting chains.
  std::vector<std::uint16_t> count_i_, count_c_, count_t_;
  IntervalCues interval_span(int p0, int p1);       // pixels [p0, p1) of one row, p1 > p0
  IntervalCues interval_histogram(int p0, int p1);  // any length: counts, mode, modal sums
  IntervalCues interval_short(int p0, int n) const; // n <= 16 with byte bins, SSE4.1, same result
  IntervalCues interval_short2(int p0, int n) const; // 16 < n <= 32, two registers per channel
};

}  // namespace epichead::vision
