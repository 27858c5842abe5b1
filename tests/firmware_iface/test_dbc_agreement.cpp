// The shipped DBC (firmware_iface/epichead.dbc), read with the DBC reader (dbc.h), describes
// exactly the frames the C++ code encodes: every BO_ is a message of the protocol, every
// message type is in the DBC, every SG_ agrees with signal_table.h in start bit, length, byte
// order, sign, factor, offset, range and unit; frames made by the C++ encoders decode through
// the DBC to the values the C++ decoders read; and the periodic messages state the rates the
// program sends them at (GenMsgCycleTime).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/dbc.h"
#include "epichead/firmware_iface/dbc_decode.h"
#include "epichead/firmware_iface/protocol.h"
#include "epichead/firmware_iface/signal_table.h"

using namespace epichead::firmware_iface;

namespace {

const Dbc& shipped_dbc() {
  static const Dbc dbc = [] {
    auto d = load_dbc(std::string(EPICHEAD_SOURCE_DIR) + "/firmware_iface/epichead.dbc");
    INFO((d ? "" : d.error()));
    REQUIRE(d.has_value());
    return *d;
  }();
  return dbc;
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(1.0, std::abs(b)); }

// Physical values of a frame by signal name, as the DBC decodes it.
std::map<std::string, double> dbc_values(const CanFrame& f) {
  const DbcMessage* m = shipped_dbc().find(f.id, f.extended());
  REQUIRE(m != nullptr);
  std::vector<DbcValue> values(m->signals.size());
  const DbcFrameDecode d = decode_frame(*m, std::span(f.data.data(), f.len), values);
  REQUIRE(d.too_short == 0);
  REQUIRE(d.values == m->signals.size());
  std::map<std::string, double> out;
  for (std::size_t i = 0; i < d.values; ++i) out[m->signals[values[i].signal].name] = values[i].physical;
  return out;
}

}  // namespace

TEST_CASE("Every DBC signal agrees with the C++ signal table") {
  const Dbc& dbc = shipped_dbc();
  CHECK(dbc.warnings.empty());
  REQUIRE(dbc.messages.size() >= static_cast<std::size_t>(kMessageTypeCount));
  std::set<MessageType> seen;
  for (const auto& msg : dbc.messages) {
    INFO("BO_ " << msg.id << " " << msg.name);
    CHECK_FALSE(msg.extended);
    const auto id = classify_id(msg.id);
    REQUIRE(id.has_value());
    seen.insert(id->type);
    CHECK(msg.name.rfind(std::string(to_string(id->type)), 0) == 0);  // name starts with the type
    CHECK(msg.length == kFrameLength);
    CHECK(msg.multiplexor == -1);
    const auto table = signal_table(id->type);
    REQUIRE(msg.signals.size() == table.size());
    for (const auto& spec : table) {
      INFO("signal " << spec.name);
      const DbcSignal* s = msg.signal(spec.name);
      REQUIRE(s != nullptr);
      CHECK(s->start_bit == spec.start_bit);
      CHECK(s->length == spec.length);
      CHECK(s->byte_order == ByteOrder::Intel);
      CHECK(s->value_type == SignalValueType::Integer);
      CHECK(s->is_signed == spec.is_signed);
      CHECK(close(s->factor, spec.factor));
      CHECK(close(s->offset, spec.offset));
      CHECK(close(s->min, spec.min));
      CHECK(close(s->max, spec.max));
      CHECK(s->unit == spec.unit);
    }
  }
  CHECK(seen.size() == static_cast<std::size_t>(kMessageTypeCount));
}

TEST_CASE("Signals of a message do not overlap and fit in 8 bytes") {
  for (int t = 0; t < kMessageTypeCount; ++t) {
    const auto table = signal_table(static_cast<MessageType>(t));
    REQUIRE_FALSE(table.empty());
    std::uint64_t used = 0;
    for (const auto& s : table) {
      INFO(to_string(static_cast<MessageType>(t)) << "." << s.name);
      REQUIRE(s.start_bit + s.length <= 64);
      const std::uint64_t mask = (s.length == 64 ? ~0ULL : ((1ULL << s.length) - 1)) << s.start_bit;
      CHECK((used & mask) == 0);
      used |= mask;
      // The stated physical range is what the raw field can carry.
      const double lo = s.is_signed ? -std::ldexp(1.0, s.length - 1) : 0.0;
      const double hi = s.is_signed ? std::ldexp(1.0, s.length - 1) - 1 : std::ldexp(1.0, s.length) - 1;
      CHECK(s.min >= lo * s.factor + s.offset - 1e-9);
      CHECK(s.max <= hi * s.factor + s.offset + 1e-9);
    }
  }
}

TEST_CASE("Frames from the C++ encoders decode through the DBC to what the C++ decoders read") {
  std::mt19937 rng(25);
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  const auto below = [&](unsigned n) { return static_cast<unsigned>(rng() % n); };
  for (int round = 0; round < 200; ++round) {
    INFO("round " << round);
    {
      ImuGyro g;
      g.value = {uniform(-45, 45), uniform(-45, 45), uniform(-45, 45)};  // beyond the range too: clipped
      g.counter = static_cast<std::uint8_t>(below(16));
      g.stamp_mod_us = imu_stamp_mod_us(rng());
      const CanFrame f = encode(g)->frame;
      const ImuGyro back = *decode_imu_gyro(f);
      auto v = dbc_values(f);
      CHECK(close(v["gyro_x"], back.value[0]));
      CHECK(close(v["gyro_y"], back.value[1]));
      CHECK(close(v["gyro_z"], back.value[2]));
      CHECK(v["counter"] == back.counter);
      CHECK(v["stamp"] == back.stamp_mod_us);
    }
    {
      ImuAccel a;
      a.value = {uniform(-170, 170), uniform(-170, 170), uniform(-170, 170)};
      a.counter = static_cast<std::uint8_t>(below(16));
      a.stamp_mod_us = imu_stamp_mod_us(rng());
      const CanFrame f = encode(a)->frame;
      const ImuAccel back = *decode_imu_accel(f);
      auto v = dbc_values(f);
      CHECK(close(v["accel_x"], back.value[0]));
      CHECK(close(v["accel_z"], back.value[2]));
      CHECK(v["stamp"] == back.stamp_mod_us);
    }
    for (int which = 0; which < 2; ++which) {
      HeadCommand c;
      c.counter = static_cast<std::uint8_t>(below(16));
      c.mode = static_cast<HeadMode>(below(4));
      c.pan_rad = uniform(-3.3, 3.3);
      c.tilt_rad = uniform(-3.3, 3.3);
      c.pan_rate_radps = uniform(-11, 11);
      c.tilt_rate_radps = uniform(-11, 11);
      HeadState s;
      s.counter = c.counter;
      s.mode = c.mode;
      s.pan_rad = c.pan_rad;
      s.tilt_rad = c.tilt_rad;
      s.pan_rate_radps = c.pan_rate_radps;
      s.tilt_rate_radps = c.tilt_rate_radps;
      const CanFrame f = which == 0 ? encode(c)->frame : encode(s)->frame;
      const HeadCommand back = which == 0 ? *decode_head_command(f) : [&] {
        const HeadState b = *decode_head_state(f);
        return HeadCommand{b.counter, b.mode, b.pan_rad, b.tilt_rad, b.pan_rate_radps, b.tilt_rate_radps, 0};
      }();
      auto v = dbc_values(f);
      CHECK(v["counter"] == back.counter);
      CHECK(v["mode"] == static_cast<int>(back.mode));
      CHECK(close(v["pan_angle"], back.pan_rad));
      CHECK(close(v["tilt_angle"], back.tilt_rad));
      CHECK(close(v["pan_rate"], back.pan_rate_radps));
      CHECK(close(v["tilt_rate"], back.tilt_rate_radps));
    }
    {
      HeadStatus st;
      st.pan_current_a = uniform(-33, 33);
      st.tilt_current_a = uniform(-33, 33);
      st.faults = static_cast<std::uint16_t>(below(512));
      st.counter = static_cast<std::uint8_t>(below(256));
      st.temperature_degc = static_cast<int>(below(256)) - 128;
      const CanFrame f = encode(st)->frame;
      const HeadStatus back = *decode_head_status(f);
      auto v = dbc_values(f);
      CHECK(close(v["pan_current"], back.pan_current_a));
      CHECK(close(v["tilt_current"], back.tilt_current_a));
      CHECK(v["faults"] == back.faults);
      CHECK(v["counter"] == back.counter);
      CHECK(v["temperature"] == back.temperature_degc);
    }
    {
      Heartbeat hb;
      hb.node = static_cast<std::uint8_t>(below(3));
      hb.state = static_cast<NodeState>(below(4));
      hb.protocol_version = static_cast<std::uint8_t>(below(256));
      hb.firmware_major = static_cast<std::uint8_t>(below(256));
      hb.firmware_minor = static_cast<std::uint8_t>(below(256));
      hb.firmware_patch = static_cast<std::uint8_t>(below(256));
      hb.uptime_s = below(1u << 24);
      const CanFrame f = encode(hb)->frame;
      const Heartbeat back = *decode_heartbeat(f);
      auto v = dbc_values(f);
      CHECK(v["state"] == static_cast<int>(back.state));
      CHECK(v["protocol_version"] == back.protocol_version);
      CHECK(v["firmware_major"] == back.firmware_major);
      CHECK(v["firmware_patch"] == back.firmware_patch);
      CHECK(v["uptime"] == back.uptime_s);
    }
    {
      TimeSyncRequest rq;
      rq.sequence = static_cast<std::uint8_t>(below(256));
      rq.controller_stamp_us = (std::uint64_t{rng()} << 16) ^ rng();
      const CanFrame f = encode(rq)->frame;
      const TimeSyncRequest back = *decode_time_sync_request(f);
      auto v = dbc_values(f);
      CHECK(v["sequence"] == back.sequence);
      CHECK(v["controller_stamp"] == static_cast<double>(back.controller_stamp_us));
      TimeSyncReply rp;
      rp.node = static_cast<std::uint8_t>(1 + below(2));
      rp.sequence = rq.sequence;
      rp.device_stamp_us = rq.controller_stamp_us / 3;
      const CanFrame g = encode(rp)->frame;
      const TimeSyncReply back_reply = *decode_time_sync_reply(g);
      auto w = dbc_values(g);
      CHECK(w["device_stamp"] == static_cast<double>(back_reply.device_stamp_us));
    }
  }
}

TEST_CASE("The DBC states the send period of every periodic message, none for the time sync replies") {
  // What the program and the devices send (docs/protocol.md, "Ids"): the control loop's 1 ms
  // tick sends a HeadCommand and the 1 kHz IMU a gyro/accel pair; time sync every 100 ms
  // (OnboardOptions::time_sync_period_s); the head's state at 200 Hz, status at 50 Hz and
  // heartbeats at 1 Hz (sim/head_dynamics.h).
  const std::map<std::string, int> expected = {
      {"TimeSyncRequest", 100}, {"HeadCommand", 1},      {"ImuGyro", 1},           {"ImuAccel", 1},
      {"HeadState", 5},         {"HeadStatus", 20},      {"Heartbeat_Controller", 1000}, {"Heartbeat_Imu", 1000},
      {"Heartbeat_Head", 1000}};
  for (const auto& m : shipped_dbc().messages) {
    INFO(m.name);
    const auto it = expected.find(m.name);
    if (it == expected.end()) {
      CHECK_FALSE(m.cycle_time_ms.has_value());  // TimeSyncReply: an answer, not periodic
    } else {
      REQUIRE(m.cycle_time_ms.has_value());
      CHECK(*m.cycle_time_ms == it->second);
    }
  }
}
