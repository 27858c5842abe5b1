#pragma once
// report.json of a run: the top-level fields every tracker's report has (frames, tracked,
// lost, track_ms_median, track_ms_p99), the same timing as thread CPU time (track_cpu_ms_*),
// the settings used, and one record per frame.
#include <expected>
#include <string>
#include <vector>

#include "visp_tracker.h"

namespace epichead::visp_compare {

struct FrameRecord {
  int frame = 0;
  FrameResult result;
};

// Nearest-rank percentile (q in [0, 1]) of `values`; NaN when empty.
double percentile(std::vector<double> values, double q);

std::expected<void, std::string> write_report(const std::string& path, const std::string& sequence_dir,
                                              TrackerMode mode, const TrackerSettings& settings,
                                              const std::vector<FrameRecord>& frames, unsigned reinitialisations);

}  // namespace epichead::visp_compare
