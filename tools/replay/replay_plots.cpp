#include "replay/replay_plots.h"

#include <filesystem>

#include "epichead/firmware_iface/can_ids.h"
#include "plot/line_plot.h"
#include "replay/dbc_analysis.h"
#include "replay/onboard_replay.h"

namespace epichead::tools::replay {

namespace fw = firmware_iface;

namespace {

std::vector<double> relative(const std::vector<double>& t, double t0) {
  std::vector<double> out;
  out.reserve(t.size());
  for (double v : t) out.push_back(v - t0);
  return out;
}

plot::Figure rates_figure(const LogAnalyzer& a, const std::string& title) {
  const RateTimeline& tl = a.timeline();
  plot::Panel rates{"frames per second by message", "time since start [s]", "frames/s", {}};
  plot::Panel load{"bus load", "time since start [s]", "%", {}};
  std::vector<double> t;
  for (std::size_t b = 0; b < tl.bins(); ++b) t.push_back((static_cast<double>(b) + 0.5) * tl.bin_s());
  for (int ch = 0; ch < tl.channels(); ++ch) {
    plot::Series s;
    s.label = ch < fw::kMessageTypeCount ? std::string(fw::to_string(static_cast<fw::MessageType>(ch)))
              : ch == LogAnalyzer::kTimelineOther ? "other ids"
                                                   : "DroneCAN RawIMU";
    double total = 0;
    for (std::size_t b = 0; b < tl.bins(); ++b) {
      s.y.push_back(tl.count(b, ch) / tl.bin_s());
      total += tl.count(b, ch);
    }
    if (total == 0) continue;
    s.x = t;
    rates.series.push_back(std::move(s));
  }
  plot::Series l{"bus load", t, {}};
  for (std::size_t b = 0; b < tl.bins(); ++b) l.y.push_back(100.0 * tl.bus_s(b) / tl.bin_s());
  load.series.push_back(std::move(l));
  return {title + ": message rates and bus load", {rates, load}};
}

plot::Figure imu_figure(const LogAnalyzer& a, const std::string& title) {
  const auto& s = a.imu_series();
  const auto t = relative(s.t(), a.first_s());
  plot::Panel gyro{"gyro (camera axes)", "time since start [s]", "rad/s", {}};
  plot::Panel accel{"accelerometer (specific force, camera axes)", "time since start [s]", "m/s^2", {}};
  const char* axes[] = {"x (right)", "y (down)", "z (forward)"};
  for (int i = 0; i < 3; ++i) {
    gyro.series.push_back({axes[i], t, s.column(static_cast<std::size_t>(i))});
    accel.series.push_back({axes[i], t, s.column(static_cast<std::size_t>(3 + i))});
  }
  return {title + ": IMU", {gyro, accel}};
}

plot::Figure head_figure(const LogAnalyzer& a, const std::string& title) {
  const auto& c = a.head_command_series();
  const auto& s = a.head_state_series();
  const auto tc = relative(c.t(), a.first_s());
  const auto ts = relative(s.t(), a.first_s());
  plot::Panel pan{"pan angle", "time since start [s]", "rad", {}};
  plot::Panel tilt{"tilt angle", "time since start [s]", "rad", {}};
  if (!c.empty()) {
    pan.series.push_back({"commanded", tc, c.column(0)});
    tilt.series.push_back({"commanded", tc, c.column(1)});
  }
  if (!s.empty()) {
    pan.series.push_back({"measured", ts, s.column(0)});
    tilt.series.push_back({"measured", ts, s.column(1)});
  }
  return {title + ": head angles against commands", {pan, tilt}};
}

}  // namespace

std::expected<std::vector<std::string>, std::string> write_plots(const LogAnalyzer& a, const std::string& dir,
                                                                 const std::string& title) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return std::unexpected(dir + ": cannot create directory (" + ec.message() + ")");
  std::vector<std::string> written;
  const auto write = [&](const plot::Figure& f, const std::string& name) -> std::expected<void, std::string> {
    const std::string path = (std::filesystem::path(dir) / name).string();
    if (auto r = plot::write_png(f, path); !r) return r;
    written.push_back(path);
    return {};
  };
  if (a.timed() && a.timeline().bins() > 0)
    if (auto r = write(rates_figure(a, title), "rates.png"); !r) return std::unexpected(r.error());
  if (!a.imu_series().empty())
    if (auto r = write(imu_figure(a, title), "imu.png"); !r) return std::unexpected(r.error());
  if (!a.head_command_series().empty() || !a.head_state_series().empty())
    if (auto r = write(head_figure(a, title), "head.png"); !r) return std::unexpected(r.error());
  return written;
}

std::expected<void, std::string> write_attitude_plot(const OnboardReplay& r, const std::string& dir,
                                                     const std::string& title) {
  const auto& s = r.attitude_series();
  if (s.empty()) return {};
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return std::unexpected(dir + ": cannot create directory (" + ec.message() + ")");
  const auto t = relative(s.t(), r.first_t_s());
  plot::Panel p{"camera attitude from the IMU (fusion predictor, re-started every second)", "time since start [s]",
                "deg", {}};
  p.series = {{"roll (about the optical axis)", t, s.column(0)},
              {"pitch (optical axis up)", t, s.column(1)},
              {"yaw (optical axis right)", t, s.column(2)}};
  return plot::write_png({title + ": attitude", {p}}, (std::filesystem::path(dir) / "attitude.png").string());
}

std::expected<void, std::string> write_signal_plot(const DbcAnalyzer& a, const std::string& path,
                                                   const std::string& title, double t0_s) {
  plot::Figure figure{title + ": DBC signals", {}};
  for (const auto& p : a.plotted()) {
    if (p.series.empty()) continue;
    plot::Panel panel{p.name, "time since start [s]", p.unit.empty() ? "value" : p.unit, {}};
    panel.series.push_back({p.name, relative(p.series.t(), t0_s), p.series.column(0)});
    figure.panels.push_back(std::move(panel));
  }
  if (figure.panels.empty()) {
    std::string names;
    for (const auto& p : a.plotted()) names += (names.empty() ? "" : ", ") + p.name;
    return std::unexpected(path + ": nothing to plot: no time-stamped frame in the log carries " + names);
  }
  const auto dir = std::filesystem::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty()) std::filesystem::create_directories(dir, ec);
  if (ec) return std::unexpected(dir.string() + ": cannot create directory (" + ec.message() + ")");
  return plot::write_png(figure, path);
}

}  // namespace epichead::tools::replay
