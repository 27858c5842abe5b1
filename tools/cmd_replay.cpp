// `epichead replay LOG [--json] [--plot DIR] [--bitrate B] [--data-bitrate B] [--imu-protocol P]
//  [--dbc FILE... [--csv FILE] [--signal MESSAGE.SIGNAL]... [--signal-plot PNG]]`:
// decodes a candump log with the epichead protocol (and DroneCAN RawIMU) and reports per CAN id
// and per message type: count, rate, gaps and jitter, counter losses and duplicates,
// out-of-range values, fault bits, bus load; frames of other protocols are counted per id.
// It re-runs the fusion predictor over the IMU stream and the head controller's watchdog over
// the IMU and head-state streams (replay/onboard_replay.h), and plots (--plot). With --dbc it
// decodes every signal the DBC files describe (replay/dbc_analysis.h): per signal its range,
// rate and values outside the DBC's range, per message its rate against GenMsgCycleTime; the
// values go to --csv and the signals named with --signal to a plot.
#include <CLI/CLI.hpp>

#include <expected>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "command.h"
#include "printable.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/dbc.h"
#include "epichead/firmware_iface/imu_protocol.h"
#include "replay/dbc_analysis.h"
#include "replay/dbc_report.h"
#include "replay/log_analysis.h"
#include "replay/onboard_replay.h"
#include "replay/replay_plots.h"
#include "replay/replay_report.h"
#include "replay/signal_csv.h"

namespace epichead::tools {
namespace {

struct Options {
  std::string log;
  bool json = false;
  std::string plot_dir;
  double bitrate = 1'000'000;  // the protocol's bit rate (docs/protocol.md)
  double data_bitrate = 2'000'000;
  std::string imu_protocol = "auto";
  double imu_rate_hz = 1000;
  std::vector<std::string> dbc_files;
  std::vector<std::string> signals;  // MESSAGE.SIGNAL to plot
  std::string signal_plot;           // PNG for them (else signals.png in plot_dir)
  std::string csv;
};

// The DBC files read and the analyzer over them; nullptr without --dbc.
std::expected<std::unique_ptr<replay::DbcAnalyzer>, std::string> dbc_analyzer(const Options& o) {
  if (o.dbc_files.empty()) {
    if (!o.signals.empty() || !o.csv.empty()) return std::unexpected("--signal and --csv need --dbc FILE");
    return nullptr;
  }
  if (!o.signals.empty() && o.plot_dir.empty() && o.signal_plot.empty())
    return std::unexpected("--signal needs --plot DIR (for signals.png) or --signal-plot FILE.png");
  std::vector<firmware_iface::Dbc> dbcs;
  for (const auto& path : o.dbc_files) {
    auto dbc = firmware_iface::load_dbc(path);
    if (!dbc) return std::unexpected(dbc.error());
    if (dbc->messages.empty()) return std::unexpected(path + ": no message (BO_) in it: is it a DBC file?");
    // What decodes only in part is said on stderr too, as it is read (the report repeats it).
    for (const auto& w : dbc->warnings) std::cerr << "epichead replay: warning: " << printable(w) << "\n";
    dbcs.push_back(std::move(*dbc));
  }
  auto a = replay::DbcAnalyzer::create(std::move(dbcs), o.signals);
  if (!a) return std::unexpected(a.error());
  return std::make_unique<replay::DbcAnalyzer>(std::move(*a));
}

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
  auto dbc = dbc_analyzer(o);
  if (!dbc) return fail("replay", dbc.error());
  auto reader = firmware_iface::CandumpReader::open(o.log);
  if (!reader) return fail("replay", reader.error());
  std::optional<replay::SignalCsv> csv;
  if (!o.csv.empty()) {
    auto opened = replay::SignalCsv::open(o.csv);
    if (!opened) return fail("replay", opened.error());
    csv = std::move(*opened);
    (*dbc)->on_value([&csv](const replay::DecodedSignal& d) { csv->write(d); });
  }

  replay::LogAnalyzer analyzer(analysis);
  firmware_iface::CandumpRecord record;
  while (reader->next(record)) {
    analyzer.add(record);
    if (*dbc) (*dbc)->add(record);
  }
  analyzer.finish();
  estimators.finish();
  if (!reader->io_error().empty()) return fail("replay", o.log + ": " + reader->io_error());
  if (csv)
    if (auto closed = csv->close(); !closed) return fail("replay", closed.error());
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
  if (*dbc && !o.signals.empty()) {
    const std::string path =
        o.signal_plot.empty() ? (std::filesystem::path(o.plot_dir) / "signals.png").string() : o.signal_plot;
    const std::string title = std::filesystem::path(o.log).filename().string();
    if (auto p = replay::write_signal_plot(**dbc, path, title, analyzer.first_s()); !p) return fail("replay", p.error());
  }
  if (o.json) {
    auto j = replay::report_json(read, analyzer);
    j["fusion"] = estimators.fusion_json();
    j["head_controller"] = estimators.controller_json();
    if (*dbc) j["dbc"] = replay::dbc_report_json(**dbc);
    std::cout << j.dump() << std::endl;
  } else {
    std::cout << replay::report_text(read, analyzer) << estimators.text();
    if (*dbc) std::cout << replay::dbc_report_text(**dbc);
  }
  return 0;
}

const CommandRegistration registration{
    "replay", "Decode a candump CAN log: per-id and per-message timing, losses, faults, bus load, plots",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("LOG", o->log, "candump log (candump -l format, or candump's default output)")->required();
      app.add_flag("--json", o->json, "Print one JSON object instead of the text report");
      app.add_option("--plot", o->plot_dir, "Write rates.png, imu.png, head.png and attitude.png (and signals.png for --signal) into this directory");
      app.add_option("--bitrate", o->bitrate, "Nominal bus bit rate for the bus load, bit/s (default 1000000, the bit rate docs/protocol.md "
                     "states for the robot's bus)");
      app.add_option("--data-bitrate", o->data_bitrate, "CAN FD data-phase bit rate, bit/s (default 2000000)");
      app.add_option("--imu-protocol", o->imu_protocol,
                     "IMU stream to plot and feed to fusion: epichead, dronecan or auto (both; default)");
      app.add_option("--imu-rate", o->imu_rate_hz, "Nominal IMU sample rate for the fusion predictor, Hz (default 1000)")
          ->check(CLI::Range(1.0, 100000.0));
      app.add_option("--dbc", o->dbc_files,
                     "DBC file(s) describing other frames on the bus: every signal is decoded and reported "
                     "(range, rate, values outside the DBC's range, period against GenMsgCycleTime)");
      app.add_option("--signal", o->signals, "MESSAGE.SIGNAL of a DBC to plot against time (repeatable)");
      app.add_option("--signal-plot", o->signal_plot, "PNG for the --signal plot (default: signals.png in --plot DIR)");
      app.add_option("--csv", o->csv,
                     "Write every decoded DBC signal value: one row per value, t_s,id,message,signal,raw,value,unit,text");
      return [o]() -> int { return run(*o); };
    }};

}  // namespace
}  // namespace epichead::tools
