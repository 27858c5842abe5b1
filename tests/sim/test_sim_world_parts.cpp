// The closed-loop simulator's parts on their own: the CAN bus's timing, drops and bus-off, and
// the head node's servo (lag, limits, backlash, timeout, stuck joint, end stop).
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/head_command.h"
#include "epichead/firmware_iface/head_status.h"
#include "epichead/hw/fake_clock.h"
#include "epichead/sim/fault_plan.h"
#include "epichead/sim/sim_can_bus.h"
#include "epichead/sim/sim_head_node.h"

using namespace epichead;
using namespace epichead::sim;
namespace fw = epichead::firmware_iface;

namespace {

fw::CanFrame numbered_frame(std::uint32_t i) {
  fw::CanFrame f;
  f.id = 0x110;
  f.len = 8;
  for (int b = 0; b < 4; ++b) f.data[b] = static_cast<std::uint8_t>(i >> (8 * b));
  return f;
}
std::uint32_t number_of(const fw::CanFrame& f) {
  std::uint32_t i = 0;
  for (int b = 0; b < 4; ++b) i |= static_cast<std::uint32_t>(f.data[b]) << (8 * b);
  return i;
}

fw::CanFrame command(fw::HeadMode mode, double pan, double tilt, double pan_rate = 0, double tilt_rate = 0) {
  fw::HeadCommand c;
  c.mode = mode;
  c.pan_rad = pan;
  c.tilt_rad = tilt;
  c.pan_rate_radps = pan_rate;
  c.tilt_rate_radps = tilt_rate;
  auto e = fw::encode(c);
  REQUIRE(e);
  return e->frame;
}

// Runs the node's servo over [t0, t1) at its rate.
void run(SimHeadNode& node, double& t, double t1, bool pan_stuck = false, bool tilt_stuck = false) {
  const double dt = 1.0 / node.dynamics().servo_rate_hz;
  for (; t < t1 - 1e-12; t += dt) node.tick(t, pan_stuck, tilt_stuck);
}

// Runs the servo to t1 with `frame` re-sent every 10 ms (as a controller would, within the timeout).
void drive(SimHeadNode& node, double& t, double t1, const fw::CanFrame& frame) {
  while (t < t1 - 1e-12) {
    node.deliver(frame, t);
    run(node, t, std::min(t1, t + 0.01));
  }
}

HeadDynamics ideal_dynamics() {
  HeadDynamics d;
  d.time_constant_s = 0.02;
  d.rate_limit_radps = 100;
  d.accel_limit_radps2 = 1e6;
  d.backlash_rad = 0;
  return d;
}

}  // namespace

TEST_CASE("bus: node frames arrive after latency plus uniform jitter, in order, with the configured drop rate",
          "[sim][bus]") {
  hw::FakeClock clock;
  const FaultPlan none;
  BusTiming timing;
  timing.latency_us = 200;
  timing.jitter_us = 100;
  timing.drop_rate = 0.1;
  constexpr int n = 10000;
  SimCanBus bus(timing, none, 7, clock, {}, n);
  for (int i = 0; i < n; ++i) bus.node_send(numbered_frame(static_cast<std::uint32_t>(i)), i * 1e-3);
  clock.set(20);
  std::vector<double> delays_us;
  std::int64_t last_number = -1;
  fw::StampedCanFrame got;
  while (bus.receive(got, 0) == hw::CanReceive::Frame) {
    const std::uint32_t i = number_of(got.frame);
    CHECK(static_cast<std::int64_t>(i) > last_number);  // never out of order
    last_number = i;
    delays_us.push_back(static_cast<double>(got.stamp_us) - i * 1000.0);
  }
  const double dropped = n - static_cast<double>(delays_us.size());
  CHECK(dropped / n == Approx(0.1).margin(0.015));
  CHECK(bus.stats().rx_dropped == static_cast<std::uint64_t>(dropped));
  CHECK(bus.counters().dropped_random == static_cast<std::uint64_t>(dropped));
  CHECK(bus.counters().rx_queue_overflow == 0);
  double sum = 0, lo = 1e9, hi = 0;
  for (double d : delays_us) {
    sum += d;
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  CHECK(lo >= 199.0);
  CHECK(lo <= 202.0);
  CHECK(hi <= 301.0);
  CHECK(hi >= 298.0);
  CHECK(sum / static_cast<double>(delays_us.size()) == Approx(250).margin(3));
}

TEST_CASE("bus: a frame is not readable before it arrives, host frames reach the nodes after the command latency",
          "[sim][bus]") {
  hw::FakeClock clock(1.0);
  const FaultPlan none;
  BusTiming timing;
  timing.latency_us = 300;
  timing.jitter_us = 0;
  timing.command_latency_us = 700;
  SimCanBus bus(timing, none, 1, clock);
  bus.node_send(numbered_frame(5), 1.0);
  fw::StampedCanFrame got;
  clock.set(1.00029);
  CHECK(bus.receive(got, 0) == hw::CanReceive::Timeout);
  clock.set(1.0003);
  REQUIRE(bus.receive(got, 0) == hw::CanReceive::Frame);
  CHECK(got.stamp_us == 1000300);
  CHECK(number_of(got.frame) == 5);
  REQUIRE(bus.send(numbered_frame(9)));
  REQUIRE(bus.next_delivery_s());
  CHECK(*bus.next_delivery_s() == Approx(1.0003 + 0.0007).epsilon(1e-12));
  CHECK(number_of(bus.pop_delivery()) == 9);
  CHECK(!bus.next_delivery_s());
  fw::CanFrame too_long = numbered_frame(1);
  too_long.len = 9;
  CHECK(!bus.send(too_long));
  CHECK(bus.stats().tx_failed == 1);
}

TEST_CASE("bus: bus-off makes receive fail, sends fail and node frames get lost, only inside its window",
          "[sim][bus][fault]") {
  hw::FakeClock clock;
  const FaultPlan plan({FaultWindow{FaultKind::bus_off, 1.0, 0.5}});
  BusTiming timing;
  timing.jitter_us = 0;
  SimCanBus bus(timing, plan, 1, clock);
  bus.node_send(numbered_frame(1), 0.9);  // arrived before the fault: kept for later
  clock.set(1.2);
  fw::StampedCanFrame got;
  CHECK(bus.receive(got, 0) == hw::CanReceive::Error);
  CHECK(std::string(bus.last_error()).find("bus-off") != std::string::npos);
  CHECK(bus.stats().state == hw::CanBusState::BusOff);
  CHECK(bus.stats().bus_off_events == 1);
  auto sent = bus.send(numbered_frame(2));
  REQUIRE(!sent);
  CHECK(sent.error().find("bus-off") != std::string::npos);
  bus.node_send(numbered_frame(3), 1.2);
  CHECK(bus.counters().lost_bus_off == 1);
  clock.set(1.5);
  CHECK(bus.stats().state == hw::CanBusState::ErrorActive);
  REQUIRE(bus.receive(got, 0) == hw::CanReceive::Frame);
  CHECK(number_of(got.frame) == 1);
  CHECK(bus.receive(got, 0) == hw::CanReceive::Timeout);
  CHECK(bus.send(numbered_frame(4)));
}

TEST_CASE("head node: a small position step follows a first-order lag with the configured time constant",
          "[sim][head]") {
  SimHeadNode node(ideal_dynamics(), 0.0, 0.0);
  double t = 0;
  node.deliver(command(fw::HeadMode::Position, 0.05, -0.02), t);
  run(node, t, 0.02);  // one time constant
  CHECK(node.current().pan_motor.angle_rad == Approx(0.05 * (1 - std::exp(-1.0))).epsilon(0.01));
  CHECK(node.current().tilt_motor.angle_rad == Approx(-0.02 * (1 - std::exp(-1.0))).epsilon(0.01));
  run(node, t, 0.06);  // three time constants
  CHECK(node.current().pan_motor.angle_rad == Approx(0.05 * (1 - std::exp(-3.0))).epsilon(0.01));
  CHECK(node.mode() == fw::HeadMode::Position);
}

TEST_CASE("head node: rate and acceleration limits bound a large step", "[sim][head]") {
  HeadDynamics d = ideal_dynamics();
  d.rate_limit_radps = 2.0;
  d.accel_limit_radps2 = 50;
  SimHeadNode node(d, 0.0, 0.0);
  double t = 0;
  node.deliver(command(fw::HeadMode::Position, 1.0, 0.0), t);
  run(node, t, 0.01);
  CHECK(node.current().pan_motor.rate_radps == Approx(0.5).margin(0.01));  // 50 rad/s^2 for 10 ms
  double peak = 0;
  for (double t1 = 0.02; t1 < 0.4 + 1e-9; t1 += 0.01) {
    node.deliver(command(fw::HeadMode::Position, 1.0, 0.0), t);  // fresh, as the controller sends
    run(node, t, t1);
    peak = std::max(peak, node.current().pan_motor.rate_radps);
  }
  CHECK(peak <= 2.0 + 1e-9);
  CHECK(peak >= 1.99);
  // 0.04 s ramp-up (0.04 rad) then 2 rad/s: about 0.76 rad at 0.4 s, still short of the step.
  CHECK(node.current().pan_motor.angle_rad == Approx(2.0 * 0.4 - 0.04).margin(0.02));
}

TEST_CASE("head node: backlash keeps the output still while the motor crosses the dead band after a reversal",
          "[sim][head]") {
  HeadDynamics d = ideal_dynamics();
  d.backlash_rad = 0.01;
  SimHeadNode node(d, 0.0, 0.0);
  double t = 0;
  drive(node, t, 0.3, command(fw::HeadMode::Position, 0.1, 0.0));
  // Driven upward: the output trails the motor by half the dead band.
  CHECK(node.current().pan_motor.angle_rad == Approx(0.1).margin(1e-5));
  CHECK(node.current().pan_out.angle_rad == Approx(0.095).margin(1e-5));
  const double out_before = node.current().pan_out.angle_rad;
  node.deliver(command(fw::HeadMode::Position, 0.05, 0.0), t);
  // Until the motor has come back by less than the dead band, the output does not move.
  while (node.current().pan_motor.angle_rad > 0.1 - 0.008) run(node, t, t + 1e-4);
  CHECK(node.current().pan_out.angle_rad == Approx(out_before).margin(1e-8));
  CHECK(node.current().pan_out.rate_radps == 0);
  drive(node, t, t + 0.3, command(fw::HeadMode::Position, 0.05, 0.0));
  // Driven downward now: the output leads by half the band on the other side.
  CHECK(node.current().pan_motor.angle_rad == Approx(0.05).margin(1e-5));
  CHECK(node.current().pan_out.angle_rad == Approx(0.055).margin(1e-5));
}

TEST_CASE("head node: once the dead band is taken up the output moves with the motor in every tick of a smooth motion",
          "[sim][head]") {
  // Motor and output advance by the same motion but round differently; the output must not
  // rest for a tick mid-motion (it did: a 30 deg/s joint showed 0 rate for one tick in ten).
  HeadDynamics d = ideal_dynamics();
  d.backlash_rad = 0.0005;
  SimHeadNode node(d, 0.0, 0.0);
  double t = 0;
  int still = 0, moving = 0;
  for (int i = 0; i < 400; ++i) {
    // A smooth rate profile, never reversing: 0.1 .. 0.6 rad/s.
    const double rate = 0.35 - 0.25 * std::cos(i * 0.02);
    node.deliver(command(fw::HeadMode::Rate, 0, 0, rate, 0), t);
    run(node, t, t + 0.001);
    if (i < 20) continue;  // the dead band is taken up first
    ++moving;
    still += node.current().pan_out.rate_radps == 0;
  }
  CHECK(moving == 380);
  CHECK(still == 0);
}

TEST_CASE("head node: no command within the timeout stops the head with the timeout fault, a command resumes it",
          "[sim][head]") {
  SimHeadNode node(ideal_dynamics(), 0.0, 0.0);
  double t = 0;
  CHECK(node.mode() == fw::HeadMode::Off);
  node.deliver(command(fw::HeadMode::Rate, 0.0, 0.0, 0.5, 0.0), t);
  run(node, t, 0.09);
  CHECK(node.current().pan_motor.rate_radps == Approx(0.5));
  CHECK((node.faults() & fw::kFaultCommandTimeout) == 0);
  run(node, t, 0.11);
  CHECK(node.mode() == fw::HeadMode::SafeStop);
  CHECK((node.faults() & fw::kFaultCommandTimeout) != 0);
  CHECK(node.current().pan_motor.rate_radps == 0);
  CHECK(node.counters().command_timeouts == 1);
  node.deliver(command(fw::HeadMode::Rate, 0.0, 0.0, 0.5, 0.0), t);
  run(node, t, 0.12);
  CHECK(node.mode() == fw::HeadMode::Rate);
  CHECK((node.faults() & fw::kFaultCommandTimeout) == 0);
  CHECK(node.current().pan_motor.rate_radps == Approx(0.5));
  fw::CanFrame garbage = command(fw::HeadMode::Rate, 0, 0);
  garbage.len = 3;
  node.deliver(garbage, t);
  CHECK(node.counters().commands_rejected == 1);
}

TEST_CASE("head node: a stuck joint does not move and reports over-current, it moves again when freed",
          "[sim][head][fault]") {
  SimHeadNode node(ideal_dynamics(), 0.0, 0.0);
  double t = 0;
  node.deliver(command(fw::HeadMode::Rate, 0.0, 0.0, 0.3, 0.3), t);
  run(node, t, 0.05, false, true);
  CHECK(node.current().tilt_motor.angle_rad == 0);
  CHECK(node.current().tilt_out.angle_rad == 0);
  CHECK(node.current().pan_motor.angle_rad == Approx(0.3 * 0.05).margin(1e-4));
  CHECK((node.faults() & fw::kFaultTiltOverCurrent) != 0);
  CHECK((node.faults() & fw::kFaultPanOverCurrent) == 0);
  CHECK(node.tilt_current_a() == Approx(node.dynamics().stall_current_a));
  const auto status = fw::decode_head_status(node.status_frame());
  REQUIRE(status);
  CHECK((status->faults & fw::kFaultTiltOverCurrent) != 0);
  run(node, t, 0.08, false, false);
  CHECK(node.current().tilt_motor.angle_rad == Approx(0.3 * 0.03).margin(1e-4));
  CHECK((node.faults() & fw::kFaultTiltOverCurrent) == 0);
}

TEST_CASE("head node: the joints stop at their end stops and say so", "[sim][head]") {
  HeadDynamics d = ideal_dynamics();
  SimHeadNode node(d, d.pan_max_rad - 0.01, 0.0);
  double t = 0;
  node.deliver(command(fw::HeadMode::Rate, 0.0, 0.0, 1.0, 0.0), t);
  run(node, t, 0.05);
  CHECK(node.current().pan_motor.angle_rad <= d.pan_max_rad);
  CHECK(node.current().pan_motor.angle_rad >= d.pan_max_rad - 1e-3);
  CHECK(node.current().pan_motor.rate_radps == 0);
  CHECK((node.faults() & fw::kFaultPanLimit) != 0);
}

TEST_CASE("bus: frames the host does not read in time overflow the receive queue and are counted", "[sim][bus]") {
  hw::FakeClock clock;
  const FaultPlan none;
  SimCanBus bus(BusTiming{}, none, 1, clock, {}, 16);
  for (int i = 0; i < 20; ++i) bus.node_send(numbered_frame(static_cast<std::uint32_t>(i)), i * 1e-3);
  CHECK(bus.counters().rx_queue_overflow == 4);
  CHECK(bus.stats().rx_dropped == 4);
}
