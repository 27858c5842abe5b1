#pragma once
// The replay tool's PNG plots: message rates and bus load over time (rates.png), gyro and
// accelerometer (imu.png), head angles against commands (head.png), the fusion predictor's
// attitude (attitude.png). A plot without data is
// not written.
#include <expected>
#include <string>
#include <vector>

#include "replay/log_analysis.h"

namespace epichead::tools::replay {

// Writes the plots into dir (created if missing); returns the files written.
std::expected<std::vector<std::string>, std::string> write_plots(const LogAnalyzer& a, const std::string& dir,
                                                                 const std::string& title);

class OnboardReplay;
// attitude.png: the camera attitude the fusion predictor integrated (not written without IMU).
std::expected<void, std::string> write_attitude_plot(const OnboardReplay& r, const std::string& dir,
                                                     const std::string& title);

}  // namespace epichead::tools::replay
