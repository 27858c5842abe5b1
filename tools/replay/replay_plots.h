#pragma once
// The replay tool's PNG plots: message rates and bus load over time (rates.png), gyro and
// accelerometer (imu.png), head angles against commands (head.png). A plot without data is
// not written.
#include <expected>
#include <string>
#include <vector>

#include "replay/log_analysis.h"

namespace epichead::tools::replay {

// Writes the plots into dir (created if missing); returns the files written.
std::expected<std::vector<std::string>, std::string> write_plots(const LogAnalyzer& a, const std::string& dir,
                                                                 const std::string& title);

}  // namespace epichead::tools::replay
