// Round trips, exact bytes and every rejection path of the CAN protocol (protocol.h).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "epichead/firmware_iface/protocol.h"
#include "epichead/firmware_iface/signal_table.h"
#include "epichead/firmware_iface/stamp_unwrap.h"
#include "epichead/firmware_iface/version.h"

using namespace epichead::firmware_iface;

namespace {

CanFrame frame_of(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.len = static_cast<std::uint8_t>(bytes.size());
  std::size_t i = 0;
  for (auto b : bytes) f.data[i++] = b;
  return f;
}

template <typename M>
M decode_as(const CanFrame& f) {
  auto m = decode(f);
  REQUIRE(m.has_value());
  REQUIRE(std::holds_alternative<M>(*m));
  return std::get<M>(*m);
}

}  // namespace

TEST_CASE("ImuGyro round trip keeps values to half an LSB, counter and stamp") {
  ImuGyro g;
  g.value = {1.0, -2.5, 34.9};  // 34.9 rad/s = 2000 deg/s fits
  g.counter = 9;
  g.stamp_mod_us = imu_stamp_mod_us(1'234'567);
  auto enc = encode(g);
  REQUIRE(enc);
  CHECK(enc->clipped == 0);
  CHECK(enc->frame.id == kIdImuGyro);
  CHECK(enc->frame.len == 8);
  const auto back = decode_as<ImuGyro>(enc->frame);
  for (int i = 0; i < 3; ++i) CHECK(std::abs(back.value[i] - g.value[i]) <= kGyroRadpsPerLsb / 2 + 1e-12);
  CHECK(back.counter == 9);
  CHECK(back.stamp_mod_us == (1'234'567u % 65536u) / 16u * 16u);
  CHECK(back.saturated == 0);
}

TEST_CASE("ImuGyro bytes are the documented little-endian layout") {
  ImuGyro g;
  g.value = {0.00125, -0.00125, 0.0};  // raw 1, -1, 0
  g.counter = 0xA;
  g.stamp_mod_us = 0xABC * 16;
  auto enc = encode(g);
  REQUIRE(enc);
  const std::array<std::uint8_t, 8> expected = {0x01, 0x00, 0xFF, 0xFF, 0x00, 0x00, 0xCA, 0xAB};
  for (int i = 0; i < 8; ++i) CHECK(enc->frame.data[i] == expected[i]);
}

TEST_CASE("ImuAccel encodes 16 g without clipping and clips and reports beyond the range") {
  ImuAccel a;
  a.value = {16 * 9.80665, 0, -16 * 9.80665};
  auto ok = encode(a);
  REQUIRE(ok);
  CHECK(ok->clipped == 0);
  a.value = {200.0, 0, -200.0};
  auto clipped = encode(a);
  REQUIRE(clipped);
  CHECK(clipped->clipped == 0b101);
  const auto back = decode_as<ImuAccel>(clipped->frame);
  CHECK(back.saturated == 0b101);  // raw at the int16 limits is flagged on decode
  CHECK(back.value[0] == Approx(32767 * kAccelMps2PerLsb));
  CHECK(back.value[2] == Approx(-32768 * kAccelMps2PerLsb));
}

TEST_CASE("Encoding a NaN is rejected with the field name") {
  ImuGyro g;
  g.value = {0, std::numeric_limits<double>::quiet_NaN(), 0};
  auto enc = encode(g);
  REQUIRE_FALSE(enc);
  CHECK(enc.error().kind == WireErrorKind::NotFinite);
  CHECK(enc.error().field == "gyro_y");
  HeadCommand c;
  c.tilt_rate_radps = std::numeric_limits<double>::infinity();
  CHECK_FALSE(encode(c));
}

TEST_CASE("HeadCommand and HeadState round trip mode, angles and rates") {
  HeadCommand c;
  c.counter = 17;  // sent modulo 16
  c.mode = HeadMode::Rate;
  c.pan_rad = 1.2345;
  c.tilt_rad = -0.5;
  c.pan_rate_radps = 2.0;  // 115 deg/s
  c.tilt_rate_radps = -3.3;
  auto enc = encode(c);
  REQUIRE(enc);
  CHECK(enc->frame.id == kIdHeadCommand);
  const auto back = decode_as<HeadCommand>(enc->frame);
  CHECK(back.counter == 1);
  CHECK(back.mode == HeadMode::Rate);
  CHECK(back.pan_rad == Approx(1.2345).margin(5e-5));
  CHECK(back.tilt_rad == Approx(-0.5).margin(5e-5));
  CHECK(back.pan_rate_radps == Approx(2.0).margin(0.0025));
  CHECK(back.tilt_rate_radps == Approx(-3.3).margin(0.0025));

  HeadState s;
  s.mode = HeadMode::SafeStop;
  s.pan_rad = -3.0;
  s.tilt_rate_radps = 20.0;  // beyond +-10.24 rad/s: clipped
  auto es = encode(s);
  REQUIRE(es);
  CHECK(es->frame.id == kIdHeadState);
  CHECK(es->clipped == (1u << 5));
  const auto sb = decode_as<HeadState>(es->frame);
  CHECK(sb.mode == HeadMode::SafeStop);
  CHECK(sb.pan_rad == Approx(-3.0).margin(5e-5));
  CHECK(sb.saturated == (1u << 3));
}

TEST_CASE("HeadStatus round trips currents, fault bits, counter and temperature") {
  HeadStatus st;
  st.pan_current_a = 1.5;
  st.tilt_current_a = -0.25;
  st.faults = kFaultTiltLimit | kFaultCommandTimeout;
  st.counter = 200;
  st.temperature_degc = -12;
  auto enc = encode(st);
  REQUIRE(enc);
  const auto back = decode_as<HeadStatus>(enc->frame);
  CHECK(back.pan_current_a == Approx(1.5));
  CHECK(back.tilt_current_a == Approx(-0.25));
  CHECK(back.faults == (kFaultTiltLimit | kFaultCommandTimeout));
  CHECK(back.counter == 200);
  CHECK(back.temperature_degc == -12);
  CHECK(head_fault_name(3) == "tilt_limit");
}

TEST_CASE("Heartbeat carries node, state, protocol and firmware version") {
  Heartbeat hb;
  hb.node = kNodeHead;
  hb.state = NodeState::Degraded;
  hb.protocol_version = kProtocolVersion;
  hb.firmware_major = 2;
  hb.firmware_minor = 7;
  hb.firmware_patch = 13;
  hb.uptime_s = 86400 * 100;
  auto enc = encode(hb);
  REQUIRE(enc);
  CHECK(enc->frame.id == 0x702);
  const auto back = decode_as<Heartbeat>(enc->frame);
  CHECK(back.node == kNodeHead);
  CHECK(back.state == NodeState::Degraded);
  CHECK(back.protocol_version == kProtocolVersion);
  CHECK(back.firmware_major == 2);
  CHECK(back.firmware_minor == 7);
  CHECK(back.firmware_patch == 13);
  CHECK(back.uptime_s == 86400u * 100u);
}

TEST_CASE("Time sync request and reply carry sequence and 48-bit clocks") {
  TimeSyncRequest rq{42, 0x0123'4567'89AB'CDEFULL};
  auto er = encode(rq);
  REQUIRE(er);
  CHECK(er->frame.id == kIdTimeSyncRequest);
  const auto r = decode_as<TimeSyncRequest>(er->frame);
  CHECK(r.sequence == 42);
  CHECK(r.controller_stamp_us == (0x0123'4567'89AB'CDEFULL & kTimeSyncStampMask));

  TimeSyncReply rp{kNodeImu, 42, 987654321};
  auto ep = encode(rp);
  REQUIRE(ep);
  CHECK(ep->frame.id == 0x081);
  const auto p = decode_as<TimeSyncReply>(ep->frame);
  CHECK(p.node == kNodeImu);
  CHECK(p.sequence == 42);
  CHECK(p.device_stamp_us == 987654321u);
  CHECK_FALSE(encode(TimeSyncReply{0, 1, 2}));  // node 0 is the controller: it does not reply
}

TEST_CASE("Short, long, remote, extended and FD frames with our ids are rejected with a reason") {
  auto good = encode(ImuGyro{})->frame;
  CanFrame shorter = good;
  shorter.len = 5;
  auto r = decode(shorter);
  REQUIRE_FALSE(r);
  CHECK(r.error().kind == WireErrorKind::ShortFrame);
  CHECK(r.error().message().find("short frame, 5 bytes") != std::string::npos);
  CHECK(r.error().message().find("0x110") != std::string::npos);

  CanFrame remote = good;
  remote.flags = CanFlags::Remote;
  CHECK(decode(remote).error().kind == WireErrorKind::NotClassicData);
  CanFrame fd = good;
  fd.flags = CanFlags::Fd;
  fd.len = 12;
  CHECK(decode(fd).error().kind == WireErrorKind::NotClassicData);
  CanFrame error = good;
  error.flags = CanFlags::Error;
  CHECK(decode(error).error().kind == WireErrorKind::NotClassicData);
  CanFrame ext = good;
  ext.flags = CanFlags::Extended;  // a 29-bit id with the same number belongs to someone else
  CHECK(decode(ext).error().kind == WireErrorKind::UnknownId);
  CHECK(decode_imu_gyro(ext).error().kind == WireErrorKind::NotClassicData);
  CanFrame longer = good;
  longer.len = 9;  // impossible on classic CAN, but a broken driver could say so
  CHECK(decode(longer).error().kind == WireErrorKind::LongFrame);

  // Every message type rejects a short frame.
  for (std::uint32_t id : {0x080u, 0x081u, 0x100u, 0x110u, 0x111u, 0x120u, 0x121u, 0x701u}) {
    CanFrame f = frame_of(id, {0, 0, 0, 0, 0, 0, 0});
    auto d = decode(f);
    REQUIRE_FALSE(d);
    CHECK(d.error().kind == WireErrorKind::ShortFrame);
  }
}

TEST_CASE("Ids outside the protocol are reported as unknown, not as errors of ours") {
  for (std::uint32_t id : {0x000u, 0x090u, 0x101u, 0x112u, 0x122u, 0x6FFu, 0x710u, 0x7FFu}) {
    auto d = decode(frame_of(id, {0, 0, 0, 0, 0, 0, 0, 0}));
    REQUIRE_FALSE(d);
    CHECK(d.error().kind == WireErrorKind::UnknownId);
  }
}

TEST_CASE("Out-of-range fields are rejected on decode and on encode") {
  SECTION("head mode 4..15") {
    auto d = decode(frame_of(kIdHeadCommand, {0x40, 0, 0, 0, 0, 0, 0, 0}));
    REQUIRE_FALSE(d);
    CHECK(d.error().kind == WireErrorKind::OutOfRange);
    CHECK(d.error().field == "mode");
    CHECK(d.error().value == 4);
    CHECK(decode(frame_of(kIdHeadState, {0xF0, 0, 0, 0, 0, 0, 0, 0})).error().field == "mode");
    HeadCommand c;
    c.mode = static_cast<HeadMode>(7);
    CHECK(encode(c).error().kind == WireErrorKind::OutOfRange);
  }
  SECTION("node state 4..255") {
    auto d = decode(frame_of(0x701, {4, 1, 0, 0, 0, 0, 0, 0}));
    REQUIRE_FALSE(d);
    CHECK(d.error().field == "state");
    Heartbeat hb;
    hb.state = static_cast<NodeState>(9);
    CHECK_FALSE(encode(hb));
  }
  SECTION("reserved fault bits") {
    auto d = decode(frame_of(kIdHeadStatus, {0, 0, 0, 0, 0x00, 0x02, 0, 0}));
    REQUIRE_FALSE(d);
    CHECK(d.error().field == "faults");
    CHECK(d.error().byte == 4);
    HeadStatus st;
    st.faults = 0x8000;
    CHECK_FALSE(encode(st));
  }
  SECTION("reserved byte of time sync") {
    auto d = decode(frame_of(kIdTimeSyncRequest, {1, 0xFF, 0, 0, 0, 0, 0, 0}));
    REQUIRE_FALSE(d);
    CHECK(d.error().field == "reserved");
    CHECK(decode(frame_of(0x082, {1, 0x01, 0, 0, 0, 0, 0, 0})).error().field == "reserved");
  }
}

TEST_CASE("Decoding needs no allocation: the result is a value variant") {
  STATIC_REQUIRE(std::is_trivially_copyable_v<Message>);
  STATIC_REQUIRE(std::variant_size_v<Message> == kMessageTypeCount);
  // message_type() follows MessageType order.
  CHECK(message_type(decode(encode(Heartbeat{})->frame).value()) == MessageType::Heartbeat);
  CHECK(message_type(decode(encode(ImuAccel{})->frame).value()) == MessageType::ImuAccel);
}

TEST_CASE("Every signal of the table is written by the encoder where the table says") {
  // Set one signal at a time to a distinctive in-range physical value through the message
  // struct, then read it back from the frame with the table's start bit and length.
  const auto read = [](const CanFrame& f, const SignalSpec& s) {
    std::uint64_t w = 0;
    for (int i = 7; i >= 0; --i) w = (w << 8) | f.data[i];
    std::uint64_t v = (w >> s.start_bit) & ((s.length == 64 ? 0 : (std::uint64_t{1} << s.length)) - 1);
    std::int64_t raw = static_cast<std::int64_t>(v);
    if (s.is_signed && (v >> (s.length - 1))) raw -= std::int64_t{1} << s.length;
    return static_cast<double>(raw) * s.factor + s.offset;
  };
  ImuGyro g;
  g.value = {1.5, -2.25, 3.125};
  g.counter = 5;
  g.stamp_mod_us = 4000;
  auto fg = encode(g)->frame;
  const auto tg = signal_table(MessageType::ImuGyro);
  CHECK(read(fg, tg[0]) == Approx(1.5));
  CHECK(read(fg, tg[1]) == Approx(-2.25));
  CHECK(read(fg, tg[2]) == Approx(3.125));
  CHECK(read(fg, tg[3]) == 5);
  CHECK(read(fg, tg[4]) == 4000);

  HeadStatus st;
  st.pan_current_a = -1.25;
  st.tilt_current_a = 2.5;
  st.faults = 0x155;
  st.counter = 77;
  st.temperature_degc = 55;
  auto fs = encode(st)->frame;
  const auto ts = signal_table(MessageType::HeadStatus);
  CHECK(read(fs, ts[0]) == Approx(-1.25));
  CHECK(read(fs, ts[1]) == Approx(2.5));
  CHECK(read(fs, ts[2]) == 0x155);
  CHECK(read(fs, ts[3]) == 77);
  CHECK(read(fs, ts[4]) == 55);

  HeadCommand c;
  c.counter = 3;
  c.mode = HeadMode::Position;
  c.pan_rad = -1.0;
  c.tilt_rad = 0.75;
  c.pan_rate_radps = 5.0;
  c.tilt_rate_radps = -7.5;
  auto fc = encode(c)->frame;
  const auto tc = signal_table(MessageType::HeadCommand);
  CHECK(read(fc, tc[0]) == 3);
  CHECK(read(fc, tc[1]) == 1);
  CHECK(read(fc, tc[2]) == Approx(-1.0));
  CHECK(read(fc, tc[3]) == Approx(0.75));
  CHECK(read(fc, tc[4]) == Approx(5.0));
  CHECK(read(fc, tc[5]) == Approx(-7.5));

  Heartbeat hb;
  hb.state = NodeState::Fault;
  hb.protocol_version = 9;
  hb.firmware_major = 1;
  hb.firmware_minor = 2;
  hb.firmware_patch = 3;
  hb.uptime_s = 0xABCDEF;
  auto fh = encode(hb)->frame;
  const auto th = signal_table(MessageType::Heartbeat);
  const double expected[] = {3, 9, 1, 2, 3, 0xABCDEF};
  for (int i = 0; i < 6; ++i) CHECK(read(fh, th[i]) == expected[i]);

  auto ft = encode(TimeSyncReply{kNodeHead, 200, 0xFFFF'FFFF'FFFFULL})->frame;
  const auto tt = signal_table(MessageType::TimeSyncReply);
  CHECK(read(ft, tt[0]) == 200);
  CHECK(read(ft, tt[1]) == static_cast<double>(0xFFFF'FFFF'FFFFULL));
}

TEST_CASE("IMU stamps unwrap across 65.536 ms wraps, and across long gaps with a time hint") {
  StampUnwrapper clock(kImuStampWrapUs);
  std::uint64_t device = 1'000'000;  // 1 s
  clock.reset(device - 1000);
  for (int i = 0; i < 200; ++i, device += 1008) CHECK(clock.unwrap(imu_stamp_mod_us(device), 1008) == device / 16 * 16);
  // 250 ms without frames: three whole wraps hidden, recovered from the receive-time hint.
  device += 250'000;
  CHECK(clock.unwrap(imu_stamp_mod_us(device), 250'000) == device / 16 * 16);
  // Without a hint the unwrapper assumes less than one wrap passed.
  StampUnwrapper naive(kImuStampWrapUs);
  CHECK(naive.unwrap(100) == 100);
  CHECK(naive.unwrap(50) == 65536 + 50);
}
