// `epichead replay LOG [--json] [--plot DIR] [--bitrate B] [--data-bitrate B] [--imu-protocol P]`:
// decodes a candump log with the epichead protocol (and DroneCAN RawIMU) and reports per CAN id
// and per message type: count, rate, gaps and jitter, counter losses and duplicates,
// out-of-range values, fault bits, bus load; frames of other protocols are counted per id.
// It re-runs the fusion predictor over the IMU stream and the head controller's watchdog over
// the IMU and head-state streams (replay/onboard_replay.h), and plots (--plot).
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "command.h"
#include "printable.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/imu_protocol.h"
#include "replay/log_analysis.h"
#include "replay/onboard_replay.h"
#include "replay/replay_plots.h"
#include "replay/replay_report.h"

namespace epichead::tools {
namespace {

struct Options {
  std::string log;
  bool json = false;
  std::string plot_dir;
  double bitrate = 500'000;
  double data_bitrate = 2'000'000;
  std::string imu_protocol = "auto";
  double imu_rate_hz = 1000;
};

int run(const Options& o) {
  replay::AnalysisOptions analysis;
  if (!(o.bitrate > 0) || !(o.data_bitrate > 0)) return fail("replay", "--bitrate and --data-bitrate must be positive");
  analysis.bitrate = o.bitrate;
  analysis.data_bitrate = o.data_bitrate;
  if (o.imu_protocol != "auto") {
    auto p = firmware_iface::parse_imu_protocol(o.imu_protocol);
    if (!p) return fail("replay", "--imu-protocol: " + p.error() + " (or 'auto')");
    analysis.imu_protocol = *p;
  }
  // The onboard estimators re-run over the log's IMU and head-state streams.
  replay::OnboardReplayOptions onboard_options;
  onboard_options.predictor.imu_rate_hz = o.imu_rate_hz;
  auto onboard = replay::OnboardReplay::create(onboard_options);
  if (!onboard) return fail("replay", onboard.error());
  replay::OnboardReplay& estimators = **onboard;
  analysis.imu_observer = [&](const replay::ImuObservation& s) { estimators.add_imu(s); };
  analysis.head_state_observer = [&](double t_s, const firmware_iface::HeadState& s) { estimators.add_head_state(t_s, s); };
  if (std::filesystem::is_directory(o.log)) return fail("replay", o.log + ": is a directory, expected a candump log");
  auto reader = firmware_iface::CandumpReader::open(o.log);
  if (!reader) return fail("replay", reader.error());

  replay::LogAnalyzer analyzer(analysis);
  firmware_iface::CandumpRecord record;
  while (reader->next(record)) analyzer.add(record);
  analyzer.finish();
  estimators.finish();
  if (!reader->io_error().empty()) return fail("replay", o.log + ": " + reader->io_error());
  if (analyzer.frames() == 0)
    return fail("replay", o.log + ": no CAN frames found (" + std::to_string(reader->malformed()) +
                              " malformed lines; expected candump log lines such as '(1436509052.249713) can0 123#DEADBEEF')");

  replay::ReadSummary read{o.log, reader->lines(), reader->malformed(), {}};
  for (const auto& e : reader->first_errors()) read.first_errors.push_back(printable(e.message(o.log)));
  if (!o.plot_dir.empty()) {
    const std::string title = std::filesystem::path(o.log).filename().string();
    auto written = replay::write_plots(analyzer, o.plot_dir, title);
    if (!written) return fail("replay", written.error());
    if (auto att = replay::write_attitude_plot(estimators, o.plot_dir, title); !att) return fail("replay", att.error());
  }
  if (o.json) {
    auto j = replay::report_json(read, analyzer);
    j["fusion"] = estimators.fusion_json();
    j["head_controller"] = estimators.controller_json();
    std::cout << j.dump() << std::endl;
  } else {
    std::cout << replay::report_text(read, analyzer) << estimators.text();
  }
  return 0;
}

const CommandRegistration registration{
    "replay", "Decode a candump CAN log: per-id and per-message timing, losses, faults, bus load, plots",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("LOG", o->log, "candump log (candump -l format, or candump's default output)")->required();
      app.add_flag("--json", o->json, "Print one JSON object instead of the text report");
      app.add_option("--plot", o->plot_dir, "Write rates.png, imu.png, head.png and attitude.png into this directory");
      app.add_option("--bitrate", o->bitrate, "Nominal bus bit rate for the bus load, bit/s (default 500000)");
      app.add_option("--data-bitrate", o->data_bitrate, "CAN FD data-phase bit rate, bit/s (default 2000000)");
      app.add_option("--imu-protocol", o->imu_protocol,
                     "IMU stream to plot and feed to fusion: epichead, dronecan or auto (both; default)");
      app.add_option("--imu-rate", o->imu_rate_hz, "Nominal IMU sample rate for the fusion predictor, Hz (default 1000)")
          ->check(CLI::Range(1.0, 100000.0));
      return [o]() -> int { return run(*o); };
    }};

}  // namespace
}  // namespace epichead::tools
