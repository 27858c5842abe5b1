#include "percentile.h"

#include <algorithm>
#include <cstddef>

namespace epichead::tools {

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const std::size_t i =
      std::min(values.size() - 1, static_cast<std::size_t>(q * static_cast<double>(values.size() - 1) + 0.5));
  return values[i];
}

}  // namespace epichead::tools
