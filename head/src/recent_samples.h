#pragma once
// The most recent N values of a measurement (a ring allocated once, a new value overwriting the
// oldest), for percentiles in a summary of a run that may last hours: memory stays constant and
// nothing allocates per sample.
#include <algorithm>
#include <cstddef>
#include <vector>

#include "epichead/common/ring_buffer.h"

namespace epichead::head {

class RecentSamples {
 public:
  explicit RecentSamples(std::size_t capacity) : values_(capacity) {}
  void push(double v) { values_.push_overwrite(v); }
  std::size_t size() const { return values_.size(); }
  // q in [0, 1] of the kept values (0 when empty). Copies: for summaries, not for the hot path.
  double percentile(double q) const {
    if (values_.empty()) return 0;
    std::vector<double> v(values_.size());
    for (std::size_t i = 0; i < v.size(); ++i) v[i] = values_[i];
    const auto k = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  }
  double max() const {
    double m = values_.empty() ? 0 : values_[0];
    for (std::size_t i = 1; i < values_.size(); ++i) m = std::max(m, values_[i]);
    return m;
  }

 private:
  common::RingBuffer<double> values_;
};

}  // namespace epichead::head
