// `epichead replay LOG [--json] [--plot DIR] [--bitrate B] [--data-bitrate B] [--imu-protocol P]
//  [--dbc FILE... [--csv FILE] [--signal MESSAGE.SIGNAL]... [--signal-plot PNG]]`:
// decodes a candump log with the epichead protocol (and DroneCAN RawIMU) and reports per CAN id
// and per message type: count, rate, gaps and jitter, counter losses and duplicates,
// out-of-range values, fault bits, bus load; frames of other protocols are counted per id.
// It re-runs the fusion predictor over the IMU stream and the head controller's watchdog over
// the IMU and head-state streams (replay/onboard_replay.h), and plots (--plot). With --dbc it
// decodes every signal the DBC files describe (replay/dbc_analysis.h): per signal its range,
// rate and values outside the DBC's range, per message its rate against GenMsgCycleTime; the
// values go to --csv and the signals named with --signal to a plot. The analysis itself is
// replay/replay_log.h, which the Python module (epichead.replay) runs too.
#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "command.h"
#include "printable.h"
#include "replay/replay_log.h"

namespace epichead::tools {
namespace {

struct Options {
  std::string log;
  bool json = false;
  std::string imu_protocol = "auto";
  replay::ReplayOptions replay;  // every other option goes straight in
};

int run(const Options& o) {
  replay::ReplayOptions r = o.replay;
  auto protocol = replay::parse_imu_protocol_or_auto(o.imu_protocol);
  if (!protocol) return fail("replay", "--imu-protocol: " + protocol.error());
  r.imu_protocol = *protocol;
  // What decodes only in part is said on stderr too, as it is read (the report repeats it).
  r.on_warning = [](const std::string& w) { std::cerr << "epichead replay: warning: " << printable(w) << "\n"; };
  auto report = replay::replay_log(o.log, r);
  if (!report) return fail("replay", report.error());
  if (o.json)
    std::cout << report->json.dump() << std::endl;
  else
    std::cout << report->text;
  return 0;
}

const CommandRegistration registration{
    "replay", "Decode a candump CAN log: per-id and per-message timing, losses, faults, bus load, plots",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("LOG", o->log, "candump log (candump -l format, or candump's default output)")->required();
      app.add_flag("--json", o->json, "Print one JSON object instead of the text report");
      app.add_option("--plot", o->replay.plot_dir, "Write rates.png, imu.png, head.png and attitude.png (and signals.png for --signal) into this directory");
      app.add_option("--bitrate", o->replay.bitrate, "Nominal bus bit rate for the bus load, bit/s (default 1000000, the bit rate docs/protocol.md "
                     "states for the robot's bus)");
      app.add_option("--data-bitrate", o->replay.data_bitrate, "CAN FD data-phase bit rate, bit/s (default 2000000)");
      app.add_option("--imu-protocol", o->imu_protocol,
                     "IMU stream to plot and feed to fusion: epichead, dronecan or auto (both; default)");
      app.add_option("--imu-rate", o->replay.imu_rate_hz, "Nominal IMU sample rate for the fusion predictor, Hz (default 1000)")
          ->check(CLI::Range(1.0, 100000.0));
      app.add_option("--dbc", o->replay.dbc_files,
                     "DBC file(s) describing other frames on the bus: every signal is decoded and reported "
                     "(range, rate, values outside the DBC's range, period against GenMsgCycleTime)");
      app.add_option("--signal", o->replay.signals, "MESSAGE.SIGNAL of a DBC to plot against time (repeatable)");
      app.add_option("--signal-plot", o->replay.signal_plot, "PNG for the --signal plot (default: signals.png in --plot DIR)");
      app.add_option("--csv", o->replay.csv,
                     "Write every decoded DBC signal value: one row per value, t_s,id,message,signal,raw,value,unit,text");
      return [o]() -> int { return run(*o); };
    }};

}  // namespace
}  // namespace epichead::tools
