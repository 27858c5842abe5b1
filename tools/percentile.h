#pragma once
// The q-quantile (0..1) of a list of values, the nearest rank (0 for an empty list): the median
// and p99 of per-frame times in report.json.
#include <vector>

namespace epichead::tools {

double percentile(std::vector<double> values, double q);

}  // namespace epichead::tools
