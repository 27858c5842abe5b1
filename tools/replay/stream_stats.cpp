#include "replay/stream_stats.h"

#include <algorithm>
#include <cmath>

namespace epichead::tools::replay {
namespace {
constexpr std::size_t kNominalGaps = 16;

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}
}  // namespace

void StreamStats::add(std::int64_t stamp_us, bool has_stamp, double bus_s) {
  ++count_;
  bus_s_ += bus_s;
  if (!has_stamp) return;
  if (timed_ == 0) {
    first_us_ = last_us_ = stamp_us;
    ++timed_;
    return;
  }
  if (stamp_us < last_us_) {
    ++backwards_;
    last_gap_us_ = -1;
    last_us_ = stamp_us;
    return;
  }
  const double gap = static_cast<double>(stamp_us - last_us_);
  last_us_ = stamp_us;
  last_gap_us_ = gap;
  ++timed_;
  gaps_.add(gap);
  if (nominal_us_ < 0) {
    first_gaps_.push_back(gap);
    if (first_gaps_.size() == kNominalGaps) {
      nominal_us_ = median(first_gaps_);
      for (double g : first_gaps_) jitter_.add(std::abs(g - nominal_us_));
      first_gaps_.clear();
    }
    return;
  }
  jitter_.add(std::abs(gap - nominal_us_));
}

double StreamStats::nominal_period_us() const {
  if (nominal_us_ >= 0) return nominal_us_;
  if (first_gaps_.empty()) return -1;
  return median(first_gaps_);
}

double StreamStats::rate_hz() const {
  if (timed_ < 2 || last_us_ <= first_us_) return 0;
  return static_cast<double>(timed_ - 1) / ((last_us_ - first_us_) * 1e-6);
}

void CounterTracker::add(int counter, double gap_us, double nominal_us) {
  if (last_ < 0) {
    last_ = counter;
    return;
  }
  const int delta = ((counter - last_) % modulo_ + modulo_) % modulo_;
  if (delta == 0) {
    ++duplicates_;
    return;
  }
  std::uint64_t lost = static_cast<std::uint64_t>(delta - 1);
  if (gap_us > 0 && nominal_us > 0) {
    // Whole counter cycles hidden in a long gap.
    const double steps = gap_us / nominal_us;
    const double cycles = std::round((steps - delta) / modulo_);
    if (cycles > 0) lost += static_cast<std::uint64_t>(cycles) * static_cast<std::uint64_t>(modulo_);
  }
  lost_ += lost;
  last_ = counter;
}

}  // namespace epichead::tools::replay
