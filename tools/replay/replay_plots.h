#pragma once
// The replay tool's PNG plots: message rates and bus load over time (rates.png), gyro and
// accelerometer (imu.png), head angles against commands (head.png), the fusion predictor's
// attitude (attitude.png); the DBC signals chosen with --signal (signals.png). A plot without
// data is not written.
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

class DbcAnalyzer;
// The DBC signals chosen with --signal, one panel each, against the time since t0_s (the log's
// start); written to `path` (a .png), its folder created if missing. An error when no chosen
// signal has a value with a time stamp.
std::expected<void, std::string> write_signal_plot(const DbcAnalyzer& a, const std::string& path,
                                                   const std::string& title, double t0_s);

}  // namespace epichead::tools::replay
