// DroneCAN uavcan.equipment.ahrs.RawIMU: a transfer built by hand from the specification
// (tail bytes, CRC-16-CCITT-FALSE seeded with signature 0x8280632C40E574B5, float16 and
// float32 fields, FRD body axes), reassembled and converted to our axes; and its failures.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "epichead/firmware_iface/dronecan_raw_imu.h"
#include "epichead/firmware_iface/imu_protocol.h"

using namespace epichead::firmware_iface;

namespace {

// Source node 42, priority 16, transfer id 7: id = 16 << 24 | 1003 << 8 | 42.
// Payload (47 bytes): timestamp 123456789 us; integration_interval 0.01f;
// rate_gyro_latest FRD (0.5, -0.25, 1.0) as float16; rate_gyro_integral (0.005, -0.0025, 0.01);
// accelerometer_latest FRD (1.5, -2.0, 9.8125) as float16; accelerometer_integral
// (0.015, -0.02, 0.098125). Transfer CRC 0xA488 (computed independently, with Python's
// struct module and a bitwise CRC), sent little-endian at the start of the first frame.
const std::uint32_t kId = 0x1003EB2A;
const std::vector<std::vector<std::uint8_t>> kFrames = {
    {0x88, 0xA4, 0x15, 0xCD, 0x5B, 0x07, 0x00, 0x87},  // start, toggle 0, tid 7
    {0x00, 0x00, 0x0A, 0xD7, 0x23, 0x3C, 0x00, 0x27},  // toggle 1
    {0x38, 0x00, 0xB4, 0x00, 0x3C, 0x0A, 0xD7, 0x07},
    {0xA3, 0x3B, 0x0A, 0xD7, 0x23, 0xBB, 0x0A, 0x27},
    {0xD7, 0x23, 0x3C, 0x00, 0x3E, 0x00, 0xC0, 0x07},
    {0xE8, 0x48, 0x8F, 0xC2, 0x75, 0x3C, 0x0A, 0x27},
    {0xD7, 0xA3, 0xBC, 0xC3, 0xF5, 0xC8, 0x3D, 0x47},  // end, toggle 0
};

StampedCanFrame make(const std::vector<std::uint8_t>& bytes, std::int64_t t_us = 0, std::uint32_t id = kId) {
  StampedCanFrame s;
  s.stamp_us = t_us;
  s.frame.id = id;
  s.frame.flags = CanFlags::Extended;
  s.frame.len = static_cast<std::uint8_t>(bytes.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) s.frame.data[i] = bytes[i];
  return s;
}

}  // namespace

TEST_CASE("A hand-built RawIMU transfer reassembles into our axes") {
  DroneCanRawImuDecoder decoder;
  for (std::size_t i = 0; i + 1 < kFrames.size(); ++i) {
    auto r = decoder.push(make(kFrames[i]));
    REQUIRE(r);
    CHECK_FALSE(r->has_value());
  }
  auto done = decoder.push(make(kFrames.back()));
  REQUIRE(done);
  REQUIRE(done->has_value());
  const DroneCanRawImu& m = **done;
  CHECK(m.source_node == 42);
  CHECK(m.transfer_id == 7);
  CHECK(m.timestamp_us == 123456789u);
  CHECK(m.integration_interval_s == Approx(0.01f));
  // ours = (right, down, forward) = (FRD y, FRD z, FRD x)
  CHECK(m.gyro_radps[0] == -0.25);
  CHECK(m.gyro_radps[1] == 1.0);
  CHECK(m.gyro_radps[2] == 0.5);
  CHECK(m.accel_mps2[0] == -2.0);
  CHECK(m.accel_mps2[1] == 9.8125);
  CHECK(m.accel_mps2[2] == 1.5);
  CHECK(m.gyro_integral[2] == Approx(0.005));
  CHECK(m.accel_integral[1] == Approx(0.098125));
  CHECK(m.covariance_count == 0);
}

TEST_CASE("Our RawIMU encoder produces exactly the hand-built frames") {
  DroneCanRawImu m;
  m.timestamp_us = 123456789;
  m.integration_interval_s = 0.01f;
  m.gyro_radps = {-0.25, 1.0, 0.5};
  m.gyro_integral = {-0.0025f, 0.01f, 0.005f};
  m.accel_mps2 = {-2.0, 9.8125, 1.5};
  m.accel_integral = {-0.02f, 0.098125f, 0.015f};
  const auto frames = encode_dronecan_raw_imu(m, 42, 7, 16);
  REQUIRE(frames.size() == kFrames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    INFO("frame " << i);
    CHECK(frames[i].id == kId);
    CHECK(frames[i].extended());
    REQUIRE(frames[i].len == kFrames[i].size());
    for (std::size_t b = 0; b < kFrames[i].size(); ++b) CHECK(frames[i].data[b] == kFrames[i][b]);
  }
}

TEST_CASE("A corrupted byte fails the transfer CRC") {
  DroneCanRawImuDecoder decoder;
  auto frames = kFrames;
  frames[3][2] ^= 0x01;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) REQUIRE(decoder.push(make(frames[i])));
  auto r = decoder.push(make(frames.back()));
  REQUIRE_FALSE(r);
  CHECK(r.error().kind == WireErrorKind::BadTransfer);
  CHECK(r.error().field == "transfer CRC");
}

TEST_CASE("A lost frame breaks the toggle sequence and the transfer is dropped") {
  DroneCanRawImuDecoder decoder;
  REQUIRE(decoder.push(make(kFrames[0])));
  REQUIRE(decoder.push(make(kFrames[1])));
  auto r = decoder.push(make(kFrames[3]));  // frame 2 lost: toggle 1 again
  REQUIRE_FALSE(r);
  CHECK(r.error().field == "toggle bit");
  auto rest = decoder.push(make(kFrames[4]));  // no transfer in progress any more
  REQUIRE_FALSE(rest);
  CHECK(rest.error().field == "continuation without start");
  // The next complete transfer decodes again.
  for (std::size_t i = 0; i + 1 < kFrames.size(); ++i) REQUIRE(decoder.push(make(kFrames[i])));
  auto ok = decoder.push(make(kFrames.back()));
  REQUIRE(ok);
  CHECK(ok->has_value());
}

TEST_CASE("Transfers from two nodes interleave, a stale transfer times out after 2 s") {
  DroneCanRawImuDecoder decoder;
  const std::uint32_t other = (kId & ~0x7Fu) | 43;
  int complete = 0;
  for (std::size_t i = 0; i < kFrames.size(); ++i) {
    for (std::uint32_t id : {kId, other}) {
      auto frame = make(kFrames[i], 0, id);
      // The other node's CRC differs only if the payload does: same payload, same CRC.
      auto r = decoder.push(frame);
      REQUIRE(r);
      complete += r->has_value() ? 1 : 0;
    }
  }
  CHECK(complete == 2);
  REQUIRE(decoder.push(make(kFrames[0], 0)));
  auto late = decoder.push(make(kFrames[1], 3'000'000));
  REQUIRE_FALSE(late);
  CHECK(decoder.transfers_timed_out() == 1);
}

TEST_CASE("Frames that are not RawIMU are ignored, malformed tail bytes are rejected") {
  DroneCanRawImuDecoder decoder;
  auto other_type = make(kFrames[0], 0, (16u << 24) | (1002u << 8) | 42u);
  auto r = decoder.push(other_type);
  REQUIRE(r);
  CHECK_FALSE(r->has_value());
  CHECK_FALSE(is_dronecan_raw_imu_frame(make(kFrames[0], 0, 0x123).frame));  // 11-bit

  auto empty = make({});
  CHECK(decoder.push(empty).error().field == "tail byte missing");
  auto toggled_start = make({0x00, 0xA7});  // start with toggle set
  CHECK(decoder.push(toggled_start).error().field == "toggle set on first frame");
  auto single_short = make({0x01, 0x02, 0xC0});  // single frame: payload too short for RawIMU
  CHECK(decoder.push(single_short).error().kind == WireErrorKind::BadTransfer);
}

TEST_CASE("float16 conversion covers normal, subnormal, infinity and rounding") {
  CHECK(half_to_float(0x3C00) == 1.0f);
  CHECK(half_to_float(0xC000) == -2.0f);
  CHECK(half_to_float(0x7BFF) == 65504.0f);
  CHECK(half_to_float(0x0001) == std::ldexp(1.0f, -24));
  CHECK(std::isinf(half_to_float(0x7C00)));
  CHECK(std::isnan(half_to_float(0x7E00)));
  for (std::uint32_t h = 0; h < 0x7C00; h += 37) CHECK(float_to_half(half_to_float(static_cast<std::uint16_t>(h))) == h);
  CHECK(float_to_half(1.0f + std::ldexp(1.0f, -11)) == 0x3C00);  // tie rounds to even
  CHECK(float_to_half(1e6f) == 0x7C00);
}

TEST_CASE("The IMU protocol is chosen by name in the configuration") {
  CHECK(parse_imu_protocol("dronecan").value() == ImuProtocol::DroneCanRawImu);
  CHECK(parse_imu_protocol("epichead").value() == ImuProtocol::Epichead);
  auto bad = parse_imu_protocol("mavlink");
  REQUIRE_FALSE(bad);
  CHECK(bad.error().find("expected 'epichead' or 'dronecan'") != std::string::npos);
}
