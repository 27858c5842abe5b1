// epichead.replay: the CAN-log replay analysis (tools/replay/replay_log.h), its report as
// Python dicts and lists (the JSON of `epichead replay --json`) or as the text report.
#include <optional>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.h"
#include "replay/replay_log.h"

namespace epichead::python {

void bind_replay(py::module_& m) {
  m.def(
      "replay",
      [](const std::string& log, double bitrate, double data_bitrate, const std::string& imu_protocol, double imu_rate_hz,
         const std::vector<std::string>& dbc, const std::vector<std::string>& signals, const std::string& csv,
         const std::string& plot_dir, const std::string& signal_plot, bool text) -> py::object {
        tools::replay::ReplayOptions o;
        o.bitrate = bitrate;
        o.data_bitrate = data_bitrate;
        auto protocol = tools::replay::parse_imu_protocol_or_auto(imu_protocol);
        if (!protocol) throw Error("imu_protocol: " + protocol.error());
        o.imu_protocol = *protocol;
        o.imu_rate_hz = imu_rate_hz;
        o.dbc_files = dbc;
        o.signals = signals;
        o.csv = csv;
        o.plot_dir = plot_dir;
        o.signal_plot = signal_plot;
        std::expected<tools::replay::ReplayReport, std::string> report;
        {
          py::gil_scoped_release release;
          report = tools::replay::replay_log(log, o);
        }
        if (!report) throw Error(report.error());
        if (text) return py::str(report->text);
        return to_python(report->json);
      },
      py::arg("log"), py::arg("bitrate") = 1'000'000.0, py::arg("data_bitrate") = 2'000'000.0,
      py::arg("imu_protocol") = "auto", py::arg("imu_rate_hz") = 1000.0, py::arg("dbc") = std::vector<std::string>{},
      py::arg("signals") = std::vector<std::string>{}, py::arg("csv") = "", py::arg("plot_dir") = "",
      py::arg("signal_plot") = "", py::arg("text") = false,
      "Replays a candump log as `epichead replay` does (the same options) and returns its report: the dict of "
      "`replay --json` (ids, messages, fusion, head_controller, dbc, ...), or with text=True the text report");
}

}  // namespace epichead::python
