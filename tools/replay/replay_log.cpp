#include "replay/replay_log.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <utility>

#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/dbc.h"
#include "printable.h"
#include "replay/dbc_analysis.h"
#include "replay/dbc_report.h"
#include "replay/log_analysis.h"
#include "replay/onboard_replay.h"
#include "replay/replay_plots.h"
#include "replay/replay_report.h"
#include "replay/signal_csv.h"

namespace epichead::tools::replay {
namespace {

// The DBC files read and the analyzer over them; nullptr without DBC files.
std::expected<std::unique_ptr<DbcAnalyzer>, std::string> dbc_analyzer(const ReplayOptions& o) {
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
    if (o.on_warning)
      for (const auto& w : dbc->warnings) o.on_warning(w);
    dbcs.push_back(std::move(*dbc));
  }
  auto a = DbcAnalyzer::create(std::move(dbcs), o.signals);
  if (!a) return std::unexpected(a.error());
  return std::make_unique<DbcAnalyzer>(std::move(*a));
}

}  // namespace

std::expected<std::optional<firmware_iface::ImuProtocol>, std::string> parse_imu_protocol_or_auto(const std::string& name) {
  if (name == "auto") return std::nullopt;
  auto p = firmware_iface::parse_imu_protocol(name);
  if (!p) return std::unexpected(p.error() + " (or 'auto')");
  return *p;
}

std::expected<ReplayReport, std::string> replay_log(const std::string& log_path, const ReplayOptions& o) {
  if (!(o.bitrate > 0) || !(o.data_bitrate > 0))
    return std::unexpected("--bitrate and --data-bitrate must be positive");
  if (!(o.imu_rate_hz >= 1 && o.imu_rate_hz <= 100000)) return std::unexpected("--imu-rate must be within 1 to 100000 Hz");
  AnalysisOptions analysis;
  analysis.bitrate = o.bitrate;
  analysis.data_bitrate = o.data_bitrate;
  analysis.imu_protocol = o.imu_protocol;
  // The onboard estimators re-run over the log's IMU and head-state streams.
  OnboardReplayOptions onboard_options;
  onboard_options.predictor.imu_rate_hz = o.imu_rate_hz;
  auto onboard = OnboardReplay::create(onboard_options);
  if (!onboard) return std::unexpected(onboard.error());
  OnboardReplay& estimators = **onboard;
  analysis.imu_observer = [&](const ImuObservation& s) { estimators.add_imu(s); };
  analysis.head_state_observer = [&](double t_s, const firmware_iface::HeadState& s) { estimators.add_head_state(t_s, s); };
  if (std::filesystem::is_directory(log_path)) return std::unexpected(log_path + ": is a directory, expected a candump log");
  auto dbc = dbc_analyzer(o);
  if (!dbc) return std::unexpected(dbc.error());
  auto reader = firmware_iface::CandumpReader::open(log_path);
  if (!reader) return std::unexpected(reader.error());
  std::optional<SignalCsv> csv;
  if (!o.csv.empty()) {
    auto opened = SignalCsv::open(o.csv);
    if (!opened) return std::unexpected(opened.error());
    csv = std::move(*opened);
    (*dbc)->on_value([&csv](const DecodedSignal& d) { csv->write(d); });
  }

  LogAnalyzer analyzer(analysis);
  firmware_iface::CandumpRecord record;
  while (reader->next(record)) {
    analyzer.add(record);
    if (*dbc) (*dbc)->add(record);
  }
  analyzer.finish();
  estimators.finish();
  if (!reader->io_error().empty()) return std::unexpected(log_path + ": " + reader->io_error());
  if (csv)
    if (auto closed = csv->close(); !closed) return std::unexpected(closed.error());
  if (analyzer.frames() == 0)
    return std::unexpected(log_path + ": no CAN frames found (" + std::to_string(reader->malformed()) +
                           " malformed lines; expected candump log lines such as '(1436509052.249713) can0 123#DEADBEEF')");

  ReadSummary read{log_path, reader->lines(), reader->malformed(), {}};
  for (const auto& e : reader->first_errors()) read.first_errors.push_back(printable(e.message(log_path)));
  const std::string title = std::filesystem::path(log_path).filename().string();
  if (!o.plot_dir.empty()) {
    if (auto written = write_plots(analyzer, o.plot_dir, title); !written) return std::unexpected(written.error());
    if (auto att = write_attitude_plot(estimators, o.plot_dir, title); !att) return std::unexpected(att.error());
  }
  if (*dbc && !o.signals.empty()) {
    const std::string path = o.signal_plot.empty() ? (std::filesystem::path(o.plot_dir) / "signals.png").string() : o.signal_plot;
    if (auto p = write_signal_plot(**dbc, path, title, analyzer.first_s()); !p) return std::unexpected(p.error());
  }
  ReplayReport report;
  report.json = report_json(read, analyzer);
  report.json["fusion"] = estimators.fusion_json();
  report.json["head_controller"] = estimators.controller_json();
  if (*dbc) report.json["dbc"] = dbc_report_json(**dbc);
  report.text = report_text(read, analyzer) + estimators.text();
  if (*dbc) report.text += dbc_report_text(**dbc);
  return report;
}

}  // namespace epichead::tools::replay
