// The IMU's clock seen from the controller: time-sync pairs give the offset to within half a
// round trip, the shortest recent round trip is used, stale and unmatched replies are refused,
// and the IMU's wrapped stamps are unwrapped against the synced clock even when the sync is as
// coarse as the longest round trip it accepts.
#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/head/device_clock_sync.h"
#include "epichead/head/imu_frame_assembler.h"

namespace {

using epichead::firmware_iface::ImuAccel;
using epichead::firmware_iface::ImuGyro;
using epichead::firmware_iface::TimeSyncReply;
using epichead::head::DeviceClockSync;
using epichead::head::ImuFrameAssembler;

constexpr double kOffset_s = 5.0;  // device clock = controller clock + 5 s

std::uint64_t device_us(double controller_s) { return static_cast<std::uint64_t>(std::llround((controller_s + kOffset_s) * 1e6)); }

// One request sent at t0_s, reaching the device after `to_device_s`, its reply back after `to_host_s`.
bool sync_once(DeviceClockSync& sync, double t0_s, double to_device_s, double to_host_s) {
  const auto request = sync.make_request(t0_s);
  TimeSyncReply reply;
  reply.sequence = request.sequence;
  reply.device_stamp_us = device_us(t0_s + to_device_s);
  return sync.on_reply(reply, t0_s + to_device_s + to_host_s);
}

double offset_error_s(const DeviceClockSync& sync, double at_s) {
  return (static_cast<double>(sync.device_us_at(at_s)) - static_cast<double>(device_us(at_s))) * 1e-6;
}

}  // namespace

TEST_CASE("clock sync: the offset is known to within half the round trip, and the shortest round trip wins",
          "[head][clock_sync]") {
  DeviceClockSync sync;
  CHECK_FALSE(sync.synced());
  // Asymmetric: 3 ms out, 1 ms back. The midpoint is 1 ms off, inside the 2 ms bound.
  REQUIRE(sync_once(sync, 1.0, 0.003, 0.001));
  REQUIRE(sync.synced());
  CHECK(sync.round_trip_s() == Approx(0.004));
  CHECK(std::abs(offset_error_s(sync, 1.5)) <= sync.max_error_s() + 1e-6);
  CHECK(offset_error_s(sync, 1.5) == Approx(0.001).margin(1e-6));
  // A symmetric 0.4 ms pair replaces it; a later slow pair does not.
  REQUIRE(sync_once(sync, 1.1, 0.0002, 0.0002));
  REQUIRE(sync_once(sync, 1.2, 0.012, 0.001));
  CHECK(sync.round_trip_s() == Approx(0.0004));
  CHECK(offset_error_s(sync, 2.0) == Approx(0.0).margin(2e-6));
  const auto c = sync.counters();
  CHECK(c.requests == 3);
  CHECK(c.replies == 3);
  CHECK(c.rejected == 0);
}

TEST_CASE("clock sync: a round trip beyond the bound, an unknown sequence and a duplicate are refused and counted",
          "[head][clock_sync]") {
  DeviceClockSync sync;
  CHECK_FALSE(sync_once(sync, 1.0, 0.015, 0.010));  // 25 ms > 20 ms
  CHECK_FALSE(sync.synced());
  TimeSyncReply stray;
  stray.sequence = 200;  // never requested
  stray.device_stamp_us = device_us(1.1);
  CHECK_FALSE(sync.on_reply(stray, 1.1));
  const auto request = sync.make_request(1.2);
  TimeSyncReply reply;
  reply.sequence = request.sequence;
  reply.device_stamp_us = device_us(1.201);
  CHECK(sync.on_reply(reply, 1.202));
  CHECK_FALSE(sync.on_reply(reply, 1.203));  // the same reply again pairs with nothing
  const auto c = sync.counters();
  CHECK(c.requests == 2);
  CHECK(c.replies == 1);
  CHECK(c.rejected == 3);
  CHECK(c.round_trip_s == Approx(0.002));
}

TEST_CASE("IMU stamps unwrap to the right 65 ms period even when the sync lags by half its longest round trip",
          "[head][clock_sync]") {
  // The worst accepted pairs: the request arrives at once, the reply waits the whole round trip.
  // The sync then reads the device clock half a round trip behind it.
  for (const double round_trip_s : {0.018, epichead::head::kMaxClockSyncRoundTrip_s - 1e-6}) {
    CAPTURE(round_trip_s);
    DeviceClockSync sync({.max_round_trip_s = epichead::head::kMaxClockSyncRoundTrip_s});
    REQUIRE(sync_once(sync, 1.0, 0.0, round_trip_s));
    REQUIRE(offset_error_s(sync, 2.0) == Approx(-0.5 * round_trip_s).margin(1e-6));

    ImuFrameAssembler assembler;
    const double taken_s = 2.0;  // device clock 7 000 000 us, a multiple of the 16 us stamp tick
    ImuGyro g;
    g.counter = 3;
    g.stamp_mod_us = epichead::firmware_iface::imu_stamp_mod_us(device_us(taken_s));
    g.value = {0.1, 0.2, 0.3};
    ImuAccel a;
    a.counter = 3;
    a.stamp_mod_us = g.stamp_mod_us;
    a.value = {0, 0, 9.81};
    const double received_s = taken_s + 0.001;  // one millisecond on the bus
    CHECK_FALSE(assembler.on_gyro(g, received_s, sync));
    const auto sample = assembler.on_accel(a, received_s, sync);
    REQUIRE(sample);
    // Off by the sync's own error, not by a wrap (65.536 ms).
    CHECK(std::abs(sample->t_s - taken_s) <= sync.max_error_s() + 1e-4);
    CHECK(sample->gyro_radps.y() == 0.2);
    CHECK(assembler.counters().samples == 1);
  }
}

TEST_CASE("IMU halves before the first sync are counted, not guessed", "[head][clock_sync]") {
  DeviceClockSync sync;
  ImuFrameAssembler assembler;
  ImuGyro g;
  CHECK_FALSE(assembler.on_gyro(g, 1.0, sync));
  CHECK(assembler.counters().unsynced == 1);
  CHECK(assembler.counters().samples == 0);
}
