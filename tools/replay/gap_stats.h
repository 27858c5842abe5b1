#pragma once
// Percentiles of a stream of non-negative values (gaps, jitter) in bounded memory: exact while
// there are at most kExact values, then a log-binned histogram (1 % wide bins, 0.1 us to
// 1e11 us) whose percentiles are within half a bin (0.6 %). The maximum is always exact.
#include <cstdint>
#include <vector>

namespace epichead::tools::replay {

class GapStats {
 public:
  static constexpr std::size_t kExact = 4096;

  void add(double value);
  std::uint64_t count() const { return count_; }
  double max() const { return max_; }
  // Nearest-rank percentile, p in [0, 1]; NaN when empty.
  double percentile(double p) const;

 private:
  void to_bins();
  std::uint64_t count_ = 0;
  double max_ = 0;
  std::vector<double> exact_;
  std::vector<std::uint64_t> bins_;  // empty while exact
};

}  // namespace epichead::tools::replay
