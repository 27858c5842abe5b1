#include "replay/rate_timeline.h"

#include <cmath>

namespace epichead::tools::replay {

void RateTimeline::add(double t_s, int channel, double bus_s) {
  if (!started_) {
    started_ = true;
    start_s_ = t_s;
  }
  if (t_s < start_s_) t_s = start_s_;  // a stamp going backwards lands in the first bin
  auto bin = static_cast<std::size_t>((t_s - start_s_) / bin_s_);
  while (bin >= kMaxBins) {
    // Merge pairs of bins: the width doubles.
    const std::size_t half = (bus_.size() + 1) / 2;
    for (std::size_t b = 0; b < half; ++b) {
      const std::size_t a = 2 * b, c = 2 * b + 1;
      for (int k = 0; k < channels_; ++k)
        counts_[b * channels_ + k] = counts_[a * channels_ + k] + (c < bus_.size() ? counts_[c * channels_ + k] : 0);
      bus_[b] = bus_[a] + (c < bus_.size() ? bus_[c] : 0);
    }
    bus_.resize(half);
    counts_.resize(half * channels_);
    bin_s_ *= 2;
    bin = static_cast<std::size_t>((t_s - start_s_) / bin_s_);
  }
  if (bin >= bus_.size()) {
    bus_.resize(bin + 1, 0);
    counts_.resize((bin + 1) * channels_, 0);
  }
  counts_[bin * channels_ + channel] += 1;
  bus_[bin] += bus_s;
}

}  // namespace epichead::tools::replay
