// `epichead replay` end to end: the real third-party logs of ../shared/data/can (counts checked
// by hand with grep/wc/awk, see each case), and logs written with our CandumpWriter that hold
// every message of the protocol with known losses, duplicates, faults and bad frames.
#include <catch2/catch.hpp>

#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/json_entry.h"
#include "common/temp_dir.h"
#include "epichead/firmware_iface/candump_writer.h"
#include "epichead/firmware_iface/dronecan_raw_imu.h"
#include "epichead/firmware_iface/protocol.h"

using nlohmann::json;
namespace fw = epichead::firmware_iface;

namespace {

struct Run {
  int status = -1;
  std::string out;
};

Run run(const std::string& args) {
  Run r;
  const std::string cmd = std::string(EPICHEAD_BIN) + " " + args + " 2>&1";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p);
  std::array<char, 4096> buf;
  std::size_t n;
  while ((n = std::fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int rc = ::pclose(p);
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  return r;
}

json replay_json(const std::string& log, const std::string& extra = "") {
  const Run r = run("replay " + log + " --json " + extra);
  INFO(r.out);
  REQUIRE(r.status == 0);
  return json::parse(r.out);
}

std::string shared(const std::string& name) { return std::string(EPICHEAD_SHARED_DATA) + "/can/" + name; }

const json& id_entry(const json& j, const std::string& id) { return epichead::testing::entry_where(j["ids"], "id", id); }

}  // namespace

TEST_CASE("Replay reads rocketcan_vcan0.log, whose last line has no newline") {
  // wc -l says 9 (no final newline); 10 frames with 10 distinct 11-bit ids, none of ours.
  const json j = replay_json(shared("rocketcan_vcan0.log"));
  CHECK(j["frames"] == 10);
  CHECK(j["lines"] == 10);
  CHECK(j["malformed_lines"] == 0);
  CHECK(j["ids"].size() == 10);
  CHECK(j["unknown_ids"] == 10);
  CHECK(j["unknown_frames"] == 10);
  CHECK(j["protocol_frames"] == 0);
  CHECK(j["duration_s"].get<double>() == Approx(1.801312).margin(1e-6));  // 1436509054.051025 - ...052.249713
  CHECK(id_entry(j, "0x6DE")["bytes"] == 6);  // last line: 6DE#68FF147114D1
}

TEST_CASE("Replay reads fesb_vcan0.log with a zero-length frame") {
  // 69 frames, 66 distinct ids; 1E6, 13F and 112 appear twice each (awk | sort | uniq -c).
  const json j = replay_json(shared("fesb_vcan0.log"));
  CHECK(j["frames"] == 69);
  CHECK(j["ids"].size() == 66);
  CHECK(id_entry(j, "0x1E6")["count"] == 2);
  CHECK(id_entry(j, "0x13F")["count"] == 2);
  CHECK(id_entry(j, "0x744")["bytes"] == 1);  // first line: 744#CD
}

TEST_CASE("Replay reads canbus_visualizer_can0.log: 29-bit ids, empty frames, per-id gaps") {
  // 2648 frames, 56 ids, all 29-bit; 183ECCE8 appears 9 times (grep -c) with a largest gap of
  // 1.141928 s (awk over its stamps); the log spans 1605726422.019523 .. 1605726431.012972.
  const json j = replay_json(shared("canbus_visualizer_can0.log"));
  CHECK(j["frames"] == 2648);
  CHECK(j["ids"].size() == 56);
  for (const auto& e : j["ids"]) CHECK(e["extended"] == true);
  const json& e = id_entry(j, "0x183ECCE8");
  CHECK(e["count"] == 9);
  CHECK(e["gap_us"]["max"].get<double>() == Approx(1141928).margin(1));
  CHECK(j["duration_s"].get<double>() == Approx(8.993449).margin(1e-6));
  CHECK(j["timestamps"] == "all");
  CHECK(j["bus_load"].get<double>() > 0);
  CHECK(j["bus_load"].get<double>() < 1);
}

TEST_CASE("Replay reads rocketcan_canfd_vcan1.log with CAN FD frames and the undefined flag F") {
  // grep: 11 frames of 123, 9 of 1F334455, 16 lines with '##'.
  const json j = replay_json(shared("rocketcan_canfd_vcan1.log"));
  CHECK(j["frames"] == 20);
  CHECK(j["malformed_lines"] == 0);
  CHECK(id_entry(j, "0x123")["count"] == 11);
  CHECK(id_entry(j, "0x1F334455")["count"] == 9);
  int fd = 0;
  for (const auto& e : j["ids"]) fd += e.value("fd", 0);
  CHECK(fd == 16);
}

TEST_CASE("Replay reads candump's default output without timestamps") {
  // awk '{print $2}' | uniq -c: 680 x 3245, 690 x 3243; no timestamps, so no rates or load.
  const json j = replay_json(shared("open3e_candump_default_format.txt"));
  CHECK(j["frames"] == 6488);
  CHECK(j["timestamps"] == "none");
  CHECK(id_entry(j, "0x680")["count"] == 3245);
  CHECK(id_entry(j, "0x690")["count"] == 3243);
  CHECK(id_entry(j, "0x680")["rate_hz"].is_null());
  CHECK(j["bus_load"].is_null());
}

TEST_CASE("Replay of a protocol log written with CandumpWriter reports losses, duplicates, faults and errors") {
  epichead::testing::TempDir dir;
  const std::string path = dir / "bus.log";
  {
    auto w = fw::CandumpWriter::open(path);
    REQUIRE(w);
    const auto put = [&](std::int64_t t_us, const fw::CanFrame& f) { REQUIRE(w->write({t_us, f}, "can0")); };
    const std::int64_t t0 = 1'700'000'000'000'000LL;
    // 1000 IMU samples at 1 kHz; sample 500..502 lost (3 gyro + 3 accel frames), sample 700's
    // gyro frame sent twice (a duplicate), sample 800's gyro saturated on x.
    for (int i = 0; i < 1000; ++i) {
      if (i >= 500 && i <= 502) continue;
      fw::ImuGyro g;
      g.value = {i == 800 ? 100.0 : 0.01 * i, 0, 0};
      g.counter = static_cast<std::uint8_t>(i & 15);
      g.stamp_mod_us = fw::imu_stamp_mod_us(static_cast<std::uint64_t>(i) * 1000);
      fw::ImuAccel a;
      a.value = {0, 9.81, 0};
      a.counter = g.counter;
      a.stamp_mod_us = g.stamp_mod_us;
      put(t0 + i * 1000, fw::encode(g)->frame);
      if (i == 700) put(t0 + i * 1000 + 10, fw::encode(g)->frame);
      put(t0 + i * 1000 + 100, fw::encode(a)->frame);
    }
    // Head command and state at 100 Hz; HeadStatus at 10 Hz with tilt_limit raised twice.
    for (int i = 0; i < 100; ++i) {
      fw::HeadCommand c;
      c.counter = static_cast<std::uint8_t>(i);
      c.mode = fw::HeadMode::Position;
      c.pan_rad = 0.01 * i;
      put(t0 + i * 10'000 + 200, fw::encode(c)->frame);
      fw::HeadState s;
      s.counter = c.counter;
      s.mode = c.mode;
      s.pan_rad = 0.01 * i - 0.005;
      put(t0 + i * 10'000 + 300, fw::encode(s)->frame);
    }
    for (int i = 0; i < 10; ++i) {
      fw::HeadStatus st;
      st.counter = static_cast<std::uint8_t>(i);
      st.faults = (i == 2 || i == 3 || i == 7) ? fw::kFaultTiltLimit : 0;
      put(t0 + i * 100'000 + 400, fw::encode(st)->frame);
    }
    fw::Heartbeat hb;
    hb.node = fw::kNodeHead;
    hb.state = fw::NodeState::Operational;
    hb.protocol_version = 1;
    hb.firmware_major = 3;
    hb.firmware_minor = 1;
    hb.firmware_patch = 4;
    put(t0 + 500, fw::encode(hb)->frame);
    // Bad frames of ours: a HeadCommand with mode 9 (out of range), a short ImuGyro.
    fw::CanFrame bad_mode = fw::encode(fw::HeadCommand{})->frame;
    bad_mode.data[0] = 0x90;
    put(t0 + 995'000, bad_mode);
    fw::CanFrame short_gyro = fw::encode(fw::ImuGyro{})->frame;
    short_gyro.len = 4;
    put(t0 + 999'500, short_gyro);
    // Foreign frames and two DroneCAN RawIMU transfers.
    fw::CanFrame other;
    other.id = 0x555;
    other.len = 2;
    put(t0 + 600, other);
    fw::DroneCanRawImu m;
    m.gyro_radps = {0.5, 0.25, -1.0};
    m.accel_mps2 = {0, 9.8125, 0};
    for (int k = 0; k < 2; ++k) {
      int n = 0;
      for (const auto& f : fw::encode_dronecan_raw_imu(m, 10, static_cast<std::uint8_t>(k))) put(t0 + 700 + k * 1000 + n++, f);
    }
    REQUIRE(w->close());
  }
  // A malformed line in the middle is reported with its number and skipped.
  {
    std::FILE* f = std::fopen(path.c_str(), "a");
    std::fputs("(1700000000.999999) can0 12#00\n", f);
    std::fclose(f);
  }
  const std::string plots = dir / "plots";
  const json j = replay_json(path, "--plot " + plots);
  const json& msgs = j["messages"];
  CHECK(msgs["ImuGyro"]["count"] == 999);  // 997 samples + 1 duplicate + 1 short frame
  CHECK(msgs["ImuGyro"]["decoded"] == 998);
  CHECK(msgs["ImuGyro"]["decode_errors"]["short frame"] == 1);
  CHECK(msgs["ImuGyro"]["counter_lost"] == 3);
  CHECK(msgs["ImuGyro"]["counter_duplicates"] == 1);
  CHECK(msgs["ImuGyro"]["saturated_frames"] == 1);
  CHECK(msgs["ImuAccel"]["count"] == 997);
  CHECK(msgs["ImuAccel"]["counter_lost"] == 3);
  CHECK(msgs["ImuAccel"]["counter_duplicates"] == 0);
  CHECK(msgs["ImuAccel"]["rate_hz"].get<double>() == Approx(1000 * 996.0 / 999).epsilon(1e-3));
  CHECK(msgs["ImuAccel"]["gap_us"]["p50"] == 1000);
  CHECK(msgs["ImuAccel"]["gap_us"]["max"] == 4000);
  CHECK(msgs["ImuAccel"]["device_gap_us"]["max"] == 4000);
  CHECK(msgs["HeadCommand"]["count"] == 101);
  CHECK(msgs["HeadCommand"]["out_of_range"] == 1);
  CHECK(msgs["HeadCommand"]["counter_lost"] == 0);
  CHECK(msgs["HeadState"]["count"] == 100);
  CHECK(j["head_faults"]["tilt_limit"]["frames"] == 3);
  CHECK(j["head_faults"]["tilt_limit"]["raised"] == 2);
  CHECK(j["heartbeats"]["2"]["firmware"] == "3.1.4");
  CHECK(j["heartbeats"]["2"]["state"] == "operational");
  CHECK(j["dronecan_raw_imu"]["transfers"] == 2);
  CHECK(j["dronecan_raw_imu"]["errors"] == 0);
  CHECK(j["imu_samples"] == 997 + 2);
  CHECK(j["unknown_frames"] == 1);
  CHECK(j["unknown_ids"] == 1);
  CHECK(j["malformed_lines"] == 1);
  REQUIRE(j["first_errors"].size() == 1);
  CHECK(j["first_errors"][0].get<std::string>().find(":" + std::to_string(j["lines"].get<int>()) + ":") !=
        std::string::npos);
  for (const char* png : {"rates.png", "imu.png", "head.png"}) {
    INFO(png);
    CHECK(std::filesystem::file_size(plots + "/" + png) > 5000);
  }
  // The text report names the same figures.
  const Run text = run("replay " + path);
  CHECK(text.status == 0);
  CHECK(text.out.find("ImuGyro") != std::string::npos);
  CHECK(text.out.find("tilt_limit") != std::string::npos);
}

TEST_CASE("Bus load counts the stuff bits of each classic frame") {
  // 1000 frames 000#, 1 ms apart: SOF, id, RTR, IDE, r0 and DLC are 19 dominant bits and the
  // CRC-15 of all zeros is 0, so 34 dominant bits need 6 stuff bits; with the 13-bit tail a
  // frame is 53 bits = 53 us at the default 1 Mbit/s (docs/protocol.md's), 106 us at 500 kbit/s,
  // over a span of 0.999 s.
  epichead::testing::TempDir dir;
  std::string text;
  for (int i = 0; i < 1000; ++i) {
    char line[64];
    std::snprintf(line, sizeof line, "(1000.%06d) can0 000#\n", i * 1000);
    text += line;
  }
  const std::string path = dir.write("zeros.log", text);
  const json j = replay_json(path);
  CHECK(j["bus_load"].get<double>() == Approx(1000 * 53e-6 / 0.999).epsilon(1e-9));
  const json j2 = replay_json(path, "--bitrate 500000");
  CHECK(j2["bus_load"].get<double>() == Approx(1000 * 106e-6 / 0.999).epsilon(1e-9));
}

TEST_CASE("Replay fails with one line for a missing file, a directory, garbage and bad options") {
  epichead::testing::TempDir dir;
  Run missing = run("replay " + dir / "nope.log");
  CHECK(missing.status != 0);
  CHECK(missing.out.find("cannot open") != std::string::npos);
  CHECK(run("replay " + dir.str()).status != 0);
  const std::string garbage = dir.write("garbage.log", std::string("\x01\x02 not a log\n\xff\xfe\n"));
  Run g = run("replay " + garbage);
  CHECK(g.status != 0);
  CHECK(g.out.find("no CAN frames") != std::string::npos);
  Run bad = run("replay " + shared("fesb_vcan0.log") + " --imu-protocol mavlink");
  CHECK(bad.status != 0);
  CHECK(bad.out.find("expected 'epichead' or 'dronecan'") != std::string::npos);
  CHECK(run("replay --help").status == 0);
}

TEST_CASE("Replay re-runs the fusion predictor and the head watchdog: a cut-out IMU stretch is a dropout, a repeated sample a duplicate") {
  epichead::testing::TempDir dir("replay_onboard");
  // A closed-loop log from the simulator (1.5 s, stabilise: no vision needed).
  const Run sim = run("sim-run mockup_walk --out '" + dir.str() + "/sim' --seconds 1.5 --mode stabilise --downscale 8 --every 0");
  INFO(sim.out);
  REQUIRE(sim.status == 0);
  const std::string original = dir / "sim/bus.log";
  const json clean = replay_json("'" + original + "'");
  INFO(clean["fusion"].dump() << clean["head_controller"].dump());
  CHECK(clean["fusion"]["imu_samples_fed"].get<int>() >= 1400);
  CHECK(clean["fusion"]["dropouts"].get<int>() == 0);
  CHECK(clean["fusion"]["growth_after_frame"]["orientation_deg_1sigma"].get<double>() < 0.5);
  CHECK(clean["head_controller"]["imu_stale_raised"].get<int>() <= 1);  // at most the start-up one

  // Cut the IMU frames (0x110, 0x111) of [1.00, 1.05) s and repeat one gyro/accel pair at 0.5 s.
  std::ifstream in(original);
  std::ofstream out(dir / "cut.log");
  std::string line, last_gyro;
  double t0 = -1;
  int cut = 0;
  bool repeated = false;
  while (std::getline(in, line)) {
    const double t = std::stod(line.substr(1));
    if (t0 < 0) t0 = t;
    const bool imu = line.find(" 110#") != std::string::npos || line.find(" 111#") != std::string::npos;
    if (imu && t - t0 >= 1.0 && t - t0 < 1.05) {
      ++cut;
      continue;
    }
    out << line << '\n';
    if (line.find(" 110#") != std::string::npos) last_gyro = line;
    if (!repeated && line.find(" 111#") != std::string::npos && t - t0 >= 0.5) {
      out << last_gyro << '\n' << line << '\n';
      repeated = true;
    }
  }
  out.close();
  REQUIRE(cut >= 90);
  REQUIRE(repeated);
  const json j = replay_json("'" + (dir / "cut.log") + "'");
  INFO(j["fusion"].dump() << j["head_controller"].dump());
  CHECK(j["fusion"]["dropouts"].get<int>() == 1);
  CHECK(j["fusion"]["dropout_total_s"].get<double>() == Approx(0.05).margin(0.003));
  CHECK(j["fusion"]["rejected"]["duplicate"].get<int>() == 1);
  // The controller's watchdog trips 10 ms into the gap (and once at start-up).
  CHECK(j["head_controller"]["imu_stale_raised"].get<int>() == clean["head_controller"]["imu_stale_raised"].get<int>() + 1);

  const Run text = run("replay '" + (dir / "cut.log") + "' --plot '" + (dir / "plots") + "'");
  CHECK(text.out.find("1 dropouts") != std::string::npos);
  CHECK(std::filesystem::exists(dir / "plots/attitude.png"));
}
