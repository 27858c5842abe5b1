// `epichead replay LOG --dbc FILE` end to end: the real anzen DBC over the real battery log of
// ../shared/data/can (counts checked by hand with grep and awk, see each case), our own DBC over
// a log written with CandumpWriter at known rates (GenMsgCycleTime checks, VAL_ texts), the CSV
// and the signal plot, and one-line errors for bad DBC files and options.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/json_entry.h"
#include "common/run_tool.h"
#include "epichead/firmware_iface/candump_writer.h"
#include "epichead/firmware_iface/protocol.h"

using nlohmann::json;
using epichead::testing::lines_of;
using epichead::testing::run_epichead;
using epichead::testing::shell_quoted;
using epichead::testing::TempDir;
namespace fw = epichead::firmware_iface;

namespace {

std::string shared(const std::string& name) { return shell_quoted(std::string(EPICHEAD_SHARED_DATA) + "/can/" + name); }
const std::string kLog = shared("canbus_visualizer_can0.log");
const std::string kAnzen = shared("canbus_visualizer_anzen.dbc");
const std::string kOurs = shell_quoted(std::string(EPICHEAD_SOURCE_DIR) + "/firmware_iface/epichead.dbc");

json replay_json(const TempDir& dir, const std::string& args) {
  const auto r = run_epichead(dir, "replay " + args + " --json");
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  return json::parse(r.out);
}

const json& message(const json& j, const std::string& name) { return epichead::testing::entry_where(j["dbc"]["messages"], "message", name); }

}  // namespace

TEST_CASE("Replay --dbc decodes the 8 ids of the real log that the anzen DBC describes") {
  TempDir dir("replay_dbc");
  const json j = replay_json(dir, kLog + " --dbc " + kAnzen);
  const json& d = j["dbc"];
  // awk: 1830CCE8 x104, 1831CCE8 x56, 1834CCE8 x48, 1838CCE8 x8, 183DCCE8 x16, 183ECCE8 x9,
  // 183FCCE8 x9, 1840CCE8 x17 = 267 of the 2648 frames; DEBUG_FRAME (0x183C..) is not in the log.
  CHECK(d["decoded_frames"] == 267);
  CHECK(d["other_frames"] == 2648 - 267);
  CHECK(d["messages"].size() == 8);
  CHECK(d["messages_not_seen"] == json::array({"DEBUG_FRAME"}));
  CHECK(d["files"][0]["warnings"].size() == 1);  // power_cumulative runs into a ninth byte

  const json& temp = message(j, "TEMP_VOLTAGE_FRAME");
  CHECK(temp["id"] == "0x183ECCE8");
  CHECK(temp["count"] == 9);
  CHECK(temp["cycle_check"] == "not stated");
  CHECK(temp["max_period_ms"].get<double>() == Approx(1141.928));  // the id's largest gap (test_replay_tool)
  CHECK(temp["signals"]["voltage_max_mono"]["count"] == 9);
  CHECK(temp["signals"]["voltage_max_mono"]["unit"] == "Volts");
  // Its rate: 8 gaps over the span of its stamps (grep 183ECCE8: the first at 1605726422.019523,
  // the last at 1605726431.006930).
  CHECK(temp["signals"]["voltage_max_mono"]["rate_hz"].get<double>() == Approx(8.0 / (1605726431.006930 - 1605726422.019523)).epsilon(1e-6));

  // The multiplexor of MONOBLOCK_VOLTAGE_FRAMES reads 13 in 8 frames (grep -c '1830CCE8#0D'),
  // outside its [0|12]; the first at 1605726422.555484.
  const json& mux = message(j, "MONOBLOCK_VOLTAGE_FRAMES")["signals"]["raw_mb_voltage_frameid"];
  CHECK(mux["multiplexor"] == true);
  CHECK(mux["out_of_range"] == 8);
  CHECK(mux["first_out_of_range_value"] == 13);
  CHECK(mux["first_out_of_range_t_s"].get<double>() == Approx(1605726422.555484).margin(1e-6));
  CHECK(mux["max"] == 13);
  // RAW_FRAME's multiplexor is 5 or 6 in 16 frames (grep -c '1834CCE8#0[56]'): no signal has those.
  CHECK(message(j, "RAW_FRAME")["unknown_multiplexer"] == 16);
  CHECK(message(j, "RAW_FRAME")["signals"]["raw_soc"]["multiplexer_value"] == 2);
  // power_cumulative is never in an 8-byte frame: every POWER_CURRENT frame is short for it.
  const json& power = message(j, "POWER_CURRENT");
  CHECK(power["too_short"] == 17);
  CHECK(power["signals"]["power_cumulative"]["count"] == 0);
  CHECK(power["signals"]["current_hall"]["count"] == 17);
}

TEST_CASE("Replay --csv writes one row per decoded value with time, id, raw and physical value and unit") {
  TempDir dir("replay_dbc_csv");
  const auto r = run_epichead(dir, "replay " + kLog + " --dbc " + kAnzen + " --csv " + shell_quoted(dir / "s.csv"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.out.find("DBC ") != std::string::npos);
  CHECK(r.out.find("raw_mb_voltage_frameid (M)") != std::string::npos);
  const auto rows = lines_of(epichead::testing::slurp(dir / "s.csv"));
  REQUIRE(rows.size() == 1 + 1069);  // canmatrix decodes the same 1069 values (tests/tools/dbc_canmatrix_oracle.py)
  CHECK(rows[0] == "t_s,id,message,signal,raw,value,unit,text");
  // The first frame, (1605726422.019523) 183ECCE8#4139E9391A444540, by hand: byte 0 = 65 -> 25;
  // voltage_max_mono 40|16@0+ = 8864 -> 8.864 V (tests/firmware_iface/test_dbc.cpp).
  CHECK(rows[1] == "1605726422.019523,0x183ECCE8,TEMP_VOLTAGE_FRAME,temperature_diode,65,25,Celcius,");
  CHECK(rows[2] == "1605726422.019523,0x183ECCE8,TEMP_VOLTAGE_FRAME,voltage_max_mono,8864,8.864,Volts,");
}

TEST_CASE("Replay --signal plots the chosen signals into the --plot folder or a named PNG") {
  TempDir dir("replay_dbc_plot");
  const std::string sig = " --signal RAW_FRAME.raw_voltage_inverter --signal MONOBLOCK_VOLTAGE_FRAMES.raw_mb1_voltage";
  auto r = run_epichead(dir, "replay " + kLog + " --dbc " + kAnzen + sig + " --plot " + shell_quoted(dir / "plots"));
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(std::filesystem::file_size(dir / "plots/signals.png") > 10000);
  CHECK(std::filesystem::exists(dir / "plots/rates.png"));
  r = run_epichead(dir, "replay " + kLog + " --dbc " + kAnzen + sig + " --signal-plot " + shell_quoted(dir / "sub/v.png"));
  REQUIRE(r.exit_code == 0);
  CHECK(std::filesystem::file_size(dir / "sub/v.png") > 10000);
}

TEST_CASE("Replay --dbc decodes the last byte of the real log's 64-byte CAN FD frames") {
  // rocketcan_canfd_vcan1.log: 1F334455 in 9 frames, 2 of them 64 bytes long ending in 88
  // (awk over the data lengths: 64 x2, 32 x4, 8 x3).
  TempDir dir("replay_dbc_fd");
  std::ofstream(dir / "fd.dbc") << "BO_ 2670937173 FdMsg: 64 N\n"  // 0x80000000 | 0x1F334455
                                  " SG_ first : 0|8@1+ (1,0) [0|0] \"\" N\n"
                                  " SG_ last : 504|8@1+ (1,0) [0|0] \"\" N\n";
  const json j = replay_json(dir, shared("rocketcan_canfd_vcan1.log") + " --dbc " + shell_quoted(dir / "fd.dbc"));
  const json& fd = message(j, "FdMsg");
  CHECK(fd["id"] == "0x1F334455");
  CHECK(fd["count"] == 9);
  CHECK(fd["other_length"] == 7);
  CHECK(fd["too_short"] == 7);
  CHECK(fd["signals"]["first"]["count"] == 9);
  CHECK(fd["signals"]["last"]["count"] == 2);
  CHECK(fd["signals"]["last"]["min"] == 0x88);
  CHECK(fd["signals"]["last"]["max"] == 0x88);
}

TEST_CASE("Replay with epichead.dbc compares each message's period with its GenMsgCycleTime") {
  TempDir dir("replay_dbc_cycle");
  const std::string path = dir / "bus.log";
  {
    auto w = fw::CandumpWriter::open(path);
    REQUIRE(w);
    const auto put = [&](std::int64_t t_us, const fw::CanFrame& f) { REQUIRE(w->write({t_us, f}, "can0")); };
    const std::int64_t t0 = 1'700'000'000'000'000LL;
    // ImuGyro every 1 ms (its cycle time) with one 10 ms hole; HeadStatus every 40 ms (DBC: 20,
    // so slower); HeadCommand every 0.5 ms (DBC: 1, so faster) in Position mode.
    for (int i = 0; i < 1000; ++i) {
      if (i >= 500 && i < 509) continue;
      fw::ImuGyro g;
      g.counter = static_cast<std::uint8_t>(i & 15);
      put(t0 + i * 1000, fw::encode(g)->frame);
    }
    for (int i = 0; i < 25; ++i) {
      fw::HeadStatus s;
      s.counter = static_cast<std::uint8_t>(i);
      put(t0 + 300 + i * 40'000, fw::encode(s)->frame);
    }
    for (int i = 0; i < 200; ++i) {
      fw::HeadCommand c;
      c.mode = fw::HeadMode::Position;
      c.pan_rad = 0.5;
      put(t0 + 100 + i * 500, fw::encode(c)->frame);
    }
  }
  const json j = replay_json(dir, shell_quoted(path) + " --dbc " + kOurs + " --csv " + shell_quoted(dir / "s.csv"));
  const json& gyro = message(j, "ImuGyro");
  CHECK(gyro["cycle_time_ms"] == 1);
  CHECK(gyro["cycle_check"] == "ok");
  CHECK(gyro["late_gaps"] == 1);
  CHECK(gyro["median_period_ms"].get<double>() == Approx(1.0).epsilon(0.01));
  CHECK(message(j, "HeadStatus")["cycle_check"] == "slower");
  CHECK(message(j, "HeadCommand")["cycle_check"] == "faster");
  CHECK(message(j, "HeadCommand")["signals"]["pan_angle"]["min"].get<double>() == Approx(0.5));
  CHECK(message(j, "HeadCommand")["signals"]["pan_angle"]["out_of_range"] == 0);
  // The epichead decoder's own report agrees on the counts.
  CHECK(j["messages"]["ImuGyro"]["count"] == message(j, "ImuGyro")["count"]);
  const std::string csv = epichead::testing::slurp(dir / "s.csv");
  CHECK(csv.find("1700000000.000100,0x100,HeadCommand,mode,1,1,,Position\n") != std::string::npos);
  CHECK(csv.find("1700000000.000100,0x100,HeadCommand,pan_angle,5000,0.5,rad,\n") != std::string::npos);
}

TEST_CASE("The simulated robot's bus keeps the periods epichead.dbc states for its messages") {
  // sim-run sends what the onboard loop sends and what the simulated IMU and head send: every
  // periodic message in the log must come at its GenMsgCycleTime.
  TempDir dir("replay_dbc_sim");
  const auto sim = run_epichead(dir, "sim-run mockup_walk --out " + shell_quoted(dir / "sim") +
                                         " --seconds 1.5 --mode stabilise --downscale 8 --every 0");
  INFO(sim.err);
  REQUIRE(sim.exit_code == 0);
  const json j = replay_json(dir, shell_quoted(dir / "sim/bus.log") + " --dbc " + kOurs);
  int periodic = 0;
  for (const auto& m : j["dbc"]["messages"]) {
    INFO(m["message"] << " median period " << m["median_period_ms"] << " ms");
    if (m["cycle_time_ms"].is_null()) continue;
    if (m["count"].get<int>() < 3) continue;  // a heartbeat or two in 1.5 s: too few gaps to judge
    ++periodic;
    CHECK(m["cycle_check"] == "ok");
    CHECK(m["late_gaps"] == 0);
    // The loop's own time sync at exactly its period (docs/protocol.md: 10 Hz), not a tick late.
    if (m["message"] == "TimeSyncRequest") CHECK(m["median_period_ms"].get<double>() == Approx(100).margin(0.01));
  }
  CHECK(periodic >= 6);  // TimeSyncRequest, HeadCommand, ImuGyro, ImuAccel, HeadState, HeadStatus
}

TEST_CASE("Replay --dbc fails with one line naming the file and line of a bad DBC, and on bad options") {
  TempDir dir("replay_dbc_bad");
  const auto one_line = [&](const std::string& args, const std::string& part) {
    const auto r = run_epichead(dir, "replay " + args);
    INFO(args << "\n" << r.err);
    CHECK(r.exit_code == 1);
    // One line of error, the last; before it only the DBC's warnings (power_cumulative).
    const auto lines = lines_of(r.err);
    REQUIRE_FALSE(lines.empty());
    CHECK(lines.back().find(part) != std::string::npos);
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) CHECK(lines[i].rfind("epichead replay: warning: ", 0) == 0);
  };
  std::ofstream(dir / "bad.dbc") << "BO_ 256 M: 8 N\n SG_ a : 0|8@2+ (1,0) [0|0] \"\" N\n";
  one_line(kLog + " --dbc " + shell_quoted(dir / "bad.dbc"),
           "bad.dbc:2: SG_ a (in M): expected the byte order after '@' (1 Intel, 0 Motorola), got '2+'");
  one_line(kLog + " --dbc " + shell_quoted(dir / "none.dbc"), "none.dbc: cannot open (No such file or directory)");
  one_line(kLog + " --dbc " + kAnzen + " --dbc " + kAnzen, "--dbc: id 0x183ECCE8 is TEMP_VOLTAGE_FRAME in ");
  one_line(kLog + " --dbc " + kAnzen + " --signal NOPE.x --plot " + shell_quoted(dir / "p"), "--signal NOPE.x: no message NOPE");
  one_line(kLog + " --dbc " + kAnzen + " --signal SOC_CURRENT.nope --plot " + shell_quoted(dir / "p"),
           "SOC_CURRENT has no signal 'nope' (it has: state_current_num, soc, input_1");
  one_line(kLog + " --dbc " + kAnzen + " --signal SOC_CURRENT.soc", "--signal needs --plot DIR");
  one_line(kLog + " --csv " + shell_quoted(dir / "x.csv"), "--signal and --csv need --dbc FILE");
  one_line(kLog + " --dbc " + kAnzen + " --signal DEBUG_FRAME.voltage_hv1 --signal-plot " + shell_quoted(dir / "d.png"),
           "nothing to plot: no time-stamped frame in the log carries DEBUG_FRAME.voltage_hv1");
}
