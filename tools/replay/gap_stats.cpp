#include "replay/gap_stats.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace epichead::tools::replay {
namespace {
constexpr double kMinValue = 0.1;      // below: the zero bin
constexpr double kBinsPerDecade = 230;  // 10^(1/230) = 1.0100: 1 % wide bins
constexpr int kDecades = 12;
constexpr std::size_t kBins = static_cast<std::size_t>(kBinsPerDecade * kDecades) + 2;

std::size_t bin_of(double v) {
  if (v < kMinValue) return 0;
  const double b = std::floor(std::log10(v / kMinValue) * kBinsPerDecade) + 1;
  return std::min(kBins - 1, static_cast<std::size_t>(b));
}
double bin_centre(std::size_t b) {
  if (b == 0) return 0;
  return kMinValue * std::pow(10.0, (static_cast<double>(b) - 0.5) / kBinsPerDecade);
}
}  // namespace

void GapStats::add(double v) {
  if (!(v >= 0)) v = 0;
  ++count_;
  max_ = std::max(max_, v);
  if (bins_.empty()) {
    exact_.push_back(v);
    if (exact_.size() > kExact) to_bins();
    return;
  }
  ++bins_[bin_of(v)];
}

void GapStats::to_bins() {
  bins_.assign(kBins, 0);
  for (double v : exact_) ++bins_[bin_of(v)];
  exact_.clear();
  exact_.shrink_to_fit();
}

double GapStats::percentile(double p) const {
  if (count_ == 0) return std::numeric_limits<double>::quiet_NaN();
  const auto rank = static_cast<std::uint64_t>(std::max(1.0, std::ceil(std::clamp(p, 0.0, 1.0) * count_)));
  if (bins_.empty()) {
    std::vector<double> sorted = exact_;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(rank - 1), sorted.end());
    return sorted[rank - 1];
  }
  std::uint64_t seen = 0;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    seen += bins_[b];
    if (seen >= rank) return std::min(max_, bin_centre(b));
  }
  return max_;
}

}  // namespace epichead::tools::replay
