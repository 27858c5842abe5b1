#pragma once
// The most recent N values of a measurement (a ring allocated once), for percentiles in a
// summary of a run that may last hours: memory stays constant and nothing allocates per sample.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace epichead::head {

class RecentSamples {
 public:
  explicit RecentSamples(std::size_t capacity) : values_(capacity) {}
  void push(double v) {
    values_[next_] = v;
    next_ = (next_ + 1) % values_.size();
    count_ = std::min(count_ + 1, values_.size());
  }
  std::size_t size() const { return count_; }
  // q in [0, 1] of the kept values (0 when empty). Copies: for summaries, not for the hot path.
  double percentile(double q) const {
    if (count_ == 0) return 0;
    std::vector<double> v(values_.begin(), values_.begin() + static_cast<std::ptrdiff_t>(count_));
    const auto k = static_cast<std::size_t>(q * static_cast<double>(count_ - 1) + 0.5);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  }
  double max() const {
    return count_ == 0 ? 0 : *std::max_element(values_.begin(), values_.begin() + static_cast<std::ptrdiff_t>(count_));
  }

 private:
  std::vector<double> values_;
  std::size_t next_ = 0, count_ = 0;
};

}  // namespace epichead::head
