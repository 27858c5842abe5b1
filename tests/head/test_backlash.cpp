// Backlash compensation (head/backlash_compensation.h) against a head whose output shaft lags
// the motor by a dead band on every reversal (the encoder is on the motor, the camera on the
// output): switched off (backlash 0) the controller is the one from before compensation, bit
// for bit.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>

#include "epichead/firmware_iface/head_command.h"
#include "epichead/head/backlash_compensation.h"
#include "epichead/head/head_controller.h"
#include "epichead/head/joint_limits.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using namespace epichead::head::testing;
namespace firmware_iface = epichead::firmware_iface;

namespace {

// FNV-1a over the wire bytes of every command, its dispatch and its mode.
struct CommandHash {
  std::uint64_t h = 1469598103934665603ull;
  void add(std::uint8_t b) { h = (h ^ b) * 1099511628211ull; }
  void add(const ControlOutput& out) {
    auto e = epichead::firmware_iface::encode(out.command);
    REQUIRE(e);
    for (std::uint8_t i = 0; i < e->frame.len; ++i) add(e->frame.data[i]);
    add(static_cast<std::uint8_t>(out.dispatch));
    add(static_cast<std::uint8_t>(out.mode));
  }
};

// Stabilise through walking bursts with gyro noise and bias, then fixate on a moving target
// with tracker noise, then Hold, Park, a bus-off and a silent head, back to Stabilise.
std::uint64_t scripted_run_hash(const HeadControllerOptions& o) {
  PlantOptions po;
  po.gyro_noise_radps = 0.008;
  po.gyro_bias_radps = Eigen::Vector3d(0.002, -0.002, 0.001);
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  HeadPlant plant(o.mount, po, walking_bursts(9.0, 4), {0.0, 0.1});
  LoopOptions lo;
  lo.target_noise_rad = 0.001;
  lo.target_velocity_mps = Eigen::Vector3d(0, 0.3, 0);
  ClosedLoop loop(std::move(*controller), std::move(plant), lo);
  loop.controller().request(ControlMode::Stabilise);
  CommandHash hash;
  for (int i = 0; i < 9000; ++i) {
    if (i == 3000) {
      loop.tracker_on = true;
      loop.controller().request(ControlMode::Fixate);
    }
    if (i == 6000) loop.controller().request(ControlMode::Hold);
    if (i == 6500) loop.controller().request(ControlMode::Park);
    if (i == 7000) loop.controller().request(ControlMode::Stabilise);
    loop.bus_off = i >= 7500 && i < 7600;
    loop.head_state_on = !(i >= 8000 && i < 8100);
    hash.add(loop.tick());
  }
  return hash.h;
}

}  // namespace

// The hash was recorded with the controller and test plant of commit a093c96 (before backlash
// compensation), Release build (GCC 12, -O3 -march=x86-64-v2). A compiler that rounds
// differently (FMA contraction on another architecture) may change it: regenerate it there
// from that commit.
TEST_CASE("with backlash 0 the commands are bit-identical to the controller before compensation",
          "[head][backlash]") {
  HeadControllerOptions o;
  o.joint_rates.command_delay_s = 0.0015;
  o.joint_rates.motor_lag_s = 0.002;
  const std::uint64_t h = scripted_run_hash(o);
  INFO("hash " << h);
  CHECK(h == 16883438856862114678ull);
}

namespace {

// Stabilise through walking bursts on a head with gear backlash; the controller's calibration
// says backlash_rad (0: no compensation). `fixed`: no commands at all (the head holds still).
RateRms stabilise_rms(double plant_backlash_rad, double controller_backlash_rad, bool fixed, double seconds,
                      std::uint64_t seed, double gyro_noise_radps = 0.008) {
  PlantOptions po;  // 2 ms motor lag, 0.5 ms command latency
  po.backlash_rad = plant_backlash_rad;
  po.gyro_noise_radps = gyro_noise_radps;
  po.gyro_bias_radps = Eigen::Vector3d(0.002, -0.002, 0.001);
  HeadControllerOptions o;
  o.joint_rates.command_delay_s = po.command_latency_s + 0.001;
  o.joint_rates.motor_lag_s = po.motor_lag_s;
  o.backlash = {controller_backlash_rad, controller_backlash_rad};
  return camera_rate_rms(o, po, seconds, seed, !fixed);
}

}  // namespace

// Measured (8 s, x/y RMS rad/s; fixed head 0.202 / 0.194 for seeds 1 / 2):
//   gyro noise 0:     no backlash 0.0183 / 0.0177, uncompensated 0.0208 / 0.0217, compensated 0.0194 / 0.0201
//   gyro noise 0.008: no backlash 0.0189 / 0.0182, uncompensated 0.0230 / 0.0220, compensated 0.0209 / 0.0202
// Compensation off is the controller from before it (the bit-identity test above).
TEST_CASE("backlash compensation lowers the camera's x/y rate RMS on a head with gear backlash", "[head][backlash]") {
  constexpr double backlash = 0.0005;  // the simulator's default head (sim/head_dynamics.h)
  const double noise = GENERATE(0.0, 0.008);
  for (std::uint64_t seed : {1u, 2u}) {
    const RateRms fixed = stabilise_rms(backlash, 0, true, 8.0, seed, noise);
    const RateRms off = stabilise_rms(backlash, 0, false, 8.0, seed, noise);
    const RateRms on = stabilise_rms(backlash, backlash, false, 8.0, seed, noise);
    const RateRms ideal = stabilise_rms(0, 0, false, 8.0, seed, noise);
    INFO("noise " << noise << " seed " << seed << ": x/y RMS fixed " << fixed.xy_radps << ", no backlash " << ideal.xy_radps << ", backlash uncompensated "
                 << off.xy_radps << ", compensated " << on.xy_radps << " rad/s");
    CHECK(fixed.xy_radps > 0.15);
    CHECK(ideal.xy_radps < off.xy_radps);
    CHECK(on.xy_radps < 0.95 * off.xy_radps);
    CHECK(off.xy_radps - on.xy_radps > 0.35 * (off.xy_radps - ideal.xy_radps));  // at least a third of what the backlash costs
  }
}

TEST_CASE("after a reversal the compensation drives the motor across the band at the joint's limits while the "
          "output rests",
          "[head][backlash]") {
  constexpr double backlash = 0.002, dt = 0.001;
  const JointLimits l = default_tilt_limits();
  BacklashCompensator b(backlash);
  b.reset(0.0);
  JointCommand motor{0.0, 0.0};
  std::uint8_t hits = 0;
  // Moving up at 0.2 rad/s: the motor pushes the output on the band's upper edge.
  for (int i = 0; i < 50; ++i) {
    motor = shape(l, motor, b.motor_rate(0.2, motor, l, dt), dt, hits);
    b.follow(motor, dt);
  }
  CHECK(b.output_angle_rad() == Approx(motor.angle_rad - 0.5 * backlash).margin(1e-12));
  CHECK(b.follow(motor, dt) == Approx(0.0).margin(1e-9));  // no time passed since: the last rate again
  // The wanted output rate reverses to -0.05 rad/s.
  int crossing_ticks = 0;
  double fastest = 0;
  double prev_rate = motor.rate_radps;
  for (int i = 0; i < 100 && b.output_angle_rad() < motor.angle_rad + 0.5 * backlash - 1e-12; ++i) {
    motor = shape(l, motor, b.motor_rate(-0.05, motor, l, dt), dt, hits);
    const double out_rate = b.follow(motor, dt);
    CHECK(std::abs(motor.rate_radps - prev_rate) <= l.accel_max_radps2 * dt + 1e-9);
    prev_rate = motor.rate_radps;
    fastest = std::min(fastest, motor.rate_radps);
    // The motor first brakes from +0.2 rad/s (pushing the output on), then crosses: the output rests.
    if (motor.rate_radps <= 0 && b.output_angle_rad() < motor.angle_rad + 0.5 * backlash - 1e-12) CHECK(out_rate == 0);
    ++crossing_ticks;
  }
  INFO("crossed " << backlash << " rad in " << crossing_ticks << " ticks, fastest " << fastest << " rad/s");
  // Uncompensated the motor would cross at 0.05 rad/s (40 ms after braking); at 60 rad/s^2 with a
  // braking curve that ends at the wanted rate it brakes (4 ms) and crosses in about
  // 2 sqrt(band / a) = 12 ms.
  CHECK(crossing_ticks <= 17);
  CHECK(fastest < -0.2);
  CHECK(b.reversals() == 1);
  // Once across, the motor pushes the output at the wanted rate.
  for (int i = 0; i < 20; ++i) {
    motor = shape(l, motor, b.motor_rate(-0.05, motor, l, dt), dt, hits);
    b.follow(motor, dt);
  }
  CHECK(motor.rate_radps == Approx(-0.05).margin(1e-9));
  CHECK(b.output_angle_rad() == Approx(motor.angle_rad + 0.5 * backlash).margin(1e-9));
}

TEST_CASE("with compensation on, closed-loop commands never exceed the rate, acceleration or position limits",
          "[head][backlash]") {
  PlantOptions po;
  po.backlash_rad = 0.01;  // a sloppy head: every reversal crosses the band at the acceleration limit
  po.gyro_noise_radps = 0.02;
  HeadControllerOptions o;
  o.backlash = {0.01, 0.01};
  o.tilt.min_rad = -0.05;  // a narrow tilt range so the braking curve acts too
  o.tilt.max_rad = 0.6;
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  HeadPlant plant(o.mount, po, walking_bursts(10.0, 9, 2.5), {0.0, 0.1});
  LoopOptions lo;
  lo.target_velocity_mps = Eigen::Vector3d(0, 1.5, -0.5);
  ClosedLoop loop(std::move(*controller), std::move(plant), lo);
  loop.controller().request(ControlMode::Stabilise);
  firmware_iface::HeadCommand prev{};
  bool have_prev = false;
  for (int i = 0; i < 10000; ++i) {
    if (i == 5000) {
      loop.tracker_on = true;
      loop.controller().request(ControlMode::Fixate);
    }
    const ControlOutput& out = loop.tick();
    if (out.mode == ControlMode::Startup) continue;
    const auto& c = out.command;
    require_within_position_and_rate_limits(c, o);
    if (have_prev) {
      REQUIRE(std::abs(c.pan_rate_radps - prev.pan_rate_radps) <= o.pan.accel_max_radps2 * 1e-3 + 1e-9);
      REQUIRE(std::abs(c.tilt_rate_radps - prev.tilt_rate_radps) <= o.tilt.accel_max_radps2 * 1e-3 + 1e-9);
    }
    prev = c;
    have_prev = true;
  }
  INFO("band crossings " << loop.controller().counters().backlash_reversals);
  CHECK(loop.controller().counters().backlash_reversals > 20);
}
