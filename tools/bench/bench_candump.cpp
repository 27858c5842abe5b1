// candump_decode: parse + protocol decode of a realistic candump log held in memory (the
// onboard recorder's mix: IMU gyro/accel pairs at 1 kHz, head command and state at 500 Hz,
// head status at 50 Hz, heartbeats, time sync, plus 10 % frames of other devices), 100 000
// frames per iteration. Frames per second = 100 000 / the median time.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "bench/bench.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/candump_writer.h"
#include "epichead/firmware_iface/protocol.h"

namespace epichead::bench {
namespace {

namespace fw = firmware_iface;

constexpr int kFrames = 100'000;

std::string make_log() {
  std::string log;
  char line[fw::kCandumpMaxLine];
  const auto put = [&](std::int64_t t_us, const fw::CanFrame& f) {
    log.append(line, fw::format_candump_line({t_us, f}, "can0", line));
  };
  std::int64_t t_us = 1'700'000'000'000'000LL;
  int n = 0;
  for (int tick = 0; n < kFrames; ++tick, t_us += 1000) {
    const double phase = tick * 1e-3;
    fw::ImuGyro g;
    g.value = {0.3 * std::sin(phase * 7), -0.2, 1.5 * std::cos(phase * 3)};
    g.counter = static_cast<std::uint8_t>(tick & 15);
    g.stamp_mod_us = fw::imu_stamp_mod_us(static_cast<std::uint64_t>(tick) * 1000);
    fw::ImuAccel a;
    a.value = {0.1, 9.81, -0.4 * std::sin(phase)};
    a.counter = g.counter;
    a.stamp_mod_us = g.stamp_mod_us;
    put(t_us + 40, fw::encode(g)->frame);
    put(t_us + 170, fw::encode(a)->frame);
    n += 2;
    if (tick % 2 == 0) {
      fw::HeadCommand c;
      c.counter = static_cast<std::uint8_t>(tick / 2);
      c.mode = fw::HeadMode::Position;
      c.pan_rad = 0.5 * std::sin(phase);
      put(t_us + 300, fw::encode(c)->frame);
      fw::HeadState s;
      s.counter = c.counter;
      s.mode = c.mode;
      s.pan_rad = c.pan_rad * 0.98;
      put(t_us + 420, fw::encode(s)->frame);
      n += 2;
    }
    if (tick % 20 == 0) {
      fw::HeadStatus st;
      st.pan_current_a = 0.8;
      st.counter = static_cast<std::uint8_t>(tick / 20);
      put(t_us + 560, fw::encode(st)->frame);
      ++n;
    }
    if (tick % 4 == 0) {  // another device's 29-bit traffic
      fw::CanFrame other;
      other.id = 0x18FEF100 | static_cast<std::uint32_t>(tick & 0xF);
      other.flags = fw::CanFlags::Extended;
      other.len = 8;
      other.data[0] = static_cast<std::uint8_t>(tick);
      put(t_us + 700, other);
      ++n;
    }
    if (tick % 1000 == 0) {
      fw::Heartbeat hb;
      hb.node = fw::kNodeImu;
      hb.state = fw::NodeState::Operational;
      hb.uptime_s = static_cast<std::uint32_t>(tick / 1000);
      put(t_us + 800, fw::encode(hb)->frame);
      ++n;
    }
  }
  return log;
}

struct State {
  std::string log = make_log();
  std::uint64_t decoded = 0, frames = 0;
};

const Registration registration{"candump_decode", [] {
  auto state = std::make_shared<State>();
  return [state] {
    auto reader = fw::CandumpReader::from_memory(state->log);
    fw::CandumpRecord record;
    while (reader.next(record)) {
      ++state->frames;
      if (auto m = fw::decode(record.frame.frame)) state->decoded += m->index() + 1;
    }
  };
}};

}  // namespace
}  // namespace epichead::bench
