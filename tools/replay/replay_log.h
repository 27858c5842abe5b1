#pragma once
// The replay analysis of one candump log, as `epichead replay` and the Python module
// (epichead.replay) run it: every frame through the log analyzer, the onboard estimators'
// replay (fusion predictor, head controller watchdog) and, with DBC files, the DBC analyzer;
// then the plots and the DBC signal CSV when asked for. The report is the JSON object that
// `replay --json` prints and the text that `replay` prints.
#include <expected>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "epichead/firmware_iface/imu_protocol.h"

namespace epichead::tools::replay {

struct ReplayOptions {
  double bitrate = 1'000'000;       // the protocol's bit rate (docs/protocol.md), bit/s
  double data_bitrate = 2'000'000;  // CAN FD data phase, bit/s
  // Which IMU stream feeds fusion and the IMU plot; nullopt: both (auto).
  std::optional<firmware_iface::ImuProtocol> imu_protocol;
  double imu_rate_hz = 1000;        // nominal IMU rate for the fusion predictor
  std::vector<std::string> dbc_files;  // other devices' DBCs: every signal decoded
  std::vector<std::string> signals;    // MESSAGE.SIGNAL of a DBC to plot (needs plot_dir or signal_plot)
  std::string csv;                     // every decoded DBC value to this CSV (needs dbc_files)
  std::string plot_dir;                // rates.png, imu.png, head.png, attitude.png (and signals.png)
  std::string signal_plot;             // PNG for the signals (default: signals.png in plot_dir)
  // Called with what a DBC decodes only in part, as it is read (the report repeats it).
  std::function<void(const std::string&)> on_warning;
};

struct ReplayReport {
  nlohmann::json json;  // what `replay --json` prints
  std::string text;     // what `replay` prints
};

// The IMU stream named on a command line or in Python: "auto" (both, nullopt) or a protocol as
// firmware_iface::parse_imu_protocol reads it.
std::expected<std::optional<firmware_iface::ImuProtocol>, std::string> parse_imu_protocol_or_auto(const std::string& name);

// Errors name the file and what is wrong (a log with no CAN frame, a DBC that does not parse,
// options that do not fit together).
std::expected<ReplayReport, std::string> replay_log(const std::string& log_path, const ReplayOptions& options);

}  // namespace epichead::tools::replay
