// The watchdog's documented safe behaviour for every fault, and recovery when the input
// returns; every transition is reported as an event with its reason.
#include <catch2/catch.hpp>

#include <cmath>
#include <optional>

#include "epichead/head/head_controller.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using namespace epichead::head::testing;

namespace {

ClosedLoop make_loop(HeadControllerOptions o = {}, bool bursts = true, LoopOptions lo = {}) {
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  PlantOptions po;
  HeadPlant plant(o.mount, po, bursts ? walking_bursts(12, 3) : std::vector<BodyBurst>{}, {0.1, 0.05});
  return ClosedLoop(std::move(*controller), std::move(plant), lo);
}

void run_until(ClosedLoop& loop, double t_s) {
  while (loop.t_s() < t_s - 1e-9) loop.tick();
}

// The first event of a kind (and mode/fault) at or after t_s.
std::optional<HeadEvent> find_event(const ClosedLoop& loop, EventKind kind, double after_s, std::optional<ControlMode> to = {},
                                    Fault fault = Fault::None) {
  for (const HeadEvent& e : loop.events()) {
    if (e.t_s < after_s - 1e-9 || e.kind != kind) continue;
    if (to && e.to != *to) continue;
    if (fault != Fault::None && e.fault != fault) continue;
    return e;
  }
  return std::nullopt;
}

}  // namespace

TEST_CASE("startup: nothing is sent before the first head state, then commands start at the measured angles",
          "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  loop.head_state_on = false;
  run_until(loop, 0.1);
  CHECK(loop.outputs().back().mode == ControlMode::Startup);
  CHECK(loop.outputs().back().dispatch == Dispatch::Withhold);
  loop.head_state_on = true;
  const ControlOutput& out = loop.tick();
  CHECK(out.mode == ControlMode::Stabilise);
  CHECK(out.dispatch == Dispatch::Send);
  CHECK(std::abs(out.command.pan_rad - 0.1) < 1e-3);
  CHECK(std::abs(out.command.tilt_rad - 0.05) < 1e-3);
  auto e = find_event(loop, EventKind::ModeChanged, 0, ControlMode::Stabilise);
  REQUIRE(e);
  CHECK(e->from == ControlMode::Startup);
  CHECK(e->reason == ModeReason::HeadStateArrived);
}

TEST_CASE("IMU dropout: stabilise falls back to hold within the timeout and returns after the recovery time",
          "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  run_until(loop, 1.0);
  loop.imu_on = false;
  run_until(loop, 1.1);
  auto raised = find_event(loop, EventKind::FaultRaised, 1.0, {}, Fault::ImuStale);
  REQUIRE(raised);
  CHECK(raised->t_s <= 1.0 + 0.010 + 0.0015);
  auto hold = find_event(loop, EventKind::ModeChanged, 1.0, ControlMode::Hold);
  REQUIRE(hold);
  CHECK(hold->reason == ModeReason::ImuStale);
  CHECK(hold->from == ControlMode::Stabilise);
  // Holding: the commanded rates have come to rest and the angle stays.
  CHECK(loop.outputs().back().mode == ControlMode::Hold);
  CHECK(loop.outputs().back().command.pan_rate_radps == 0);
  CHECK(loop.outputs().back().command.tilt_rate_radps == 0);
  loop.imu_on = true;
  run_until(loop, 1.3);
  auto cleared = find_event(loop, EventKind::FaultCleared, 1.1, {}, Fault::ImuStale);
  REQUIRE(cleared);
  CHECK(cleared->t_s == Approx(1.15).margin(0.0021));
  auto back = find_event(loop, EventKind::ModeChanged, 1.1, ControlMode::Stabilise);
  REQUIRE(back);
  CHECK(back->reason == ModeReason::Recovered);
  CHECK(loop.outputs().back().mode == ControlMode::Stabilise);
}

TEST_CASE("a short IMU gap under the timeout changes nothing", "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  run_until(loop, 1.0);
  loop.imu_on = false;
  run_until(loop, 1.008);
  loop.imu_on = true;
  run_until(loop, 1.2);
  CHECK_FALSE(find_event(loop, EventKind::FaultRaised, 0.5));
  CHECK(loop.outputs().back().mode == ControlMode::Stabilise);
}

TEST_CASE("bus-off: commands are withheld in the safe mode, and after recovery restart from the measured angles",
          "[head][watchdog]") {
  for (ControlMode safe : {ControlMode::Hold, ControlMode::Park}) {
    HeadControllerOptions o;
    o.safe_mode = safe;
    ClosedLoop loop = make_loop(o);
    run_until(loop, 1.0);
    loop.bus_off = true;
    const ControlOutput first = loop.tick();
    CHECK(first.dispatch == Dispatch::Withhold);
    CHECK(first.mode == safe);
    auto e = find_event(loop, EventKind::ModeChanged, 1.0, safe);
    REQUIRE(e);
    CHECK(e->reason == ModeReason::BusOff);
    run_until(loop, 1.2);
    CHECK(loop.outputs().back().dispatch == Dispatch::Withhold);
    CHECK(has(loop.outputs().back().faults, Fault::BusOff));
    loop.bus_off = false;
    run_until(loop, 1.2 + 0.048);
    CHECK(loop.outputs().back().dispatch == Dispatch::Withhold);  // not yet: the bus must stay up 50 ms
    run_until(loop, 1.2 + 0.053);
    const ControlOutput& out = loop.outputs().back();
    CHECK(out.dispatch == Dispatch::Send);
    CHECK(out.mode == ControlMode::Stabilise);
    // The head stood still while the bus was off (its own command timeout): the command
    // restarts from its measured angles, not from where the controller had been.
    CHECK(std::abs(out.command.pan_rad - loop.plant().angles().pan_rad) < 0.01);
    CHECK(std::abs(out.command.tilt_rad - loop.plant().angles().tilt_rad) < 0.01);
    auto back = find_event(loop, EventKind::ModeChanged, 1.2, ControlMode::Stabilise);
    REQUIRE(back);
    CHECK(back->reason == ModeReason::Recovered);
  }
}

TEST_CASE("silent head: commands keep going in hold while no head state arrives, stabilise returns after",
          "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  run_until(loop, 1.0);
  loop.head_state_on = false;
  run_until(loop, 1.1);
  auto e = find_event(loop, EventKind::ModeChanged, 1.0, ControlMode::Hold);
  REQUIRE(e);
  CHECK(e->reason == ModeReason::HeadStateStale);
  CHECK(e->t_s <= 1.0 + 0.020 + 0.0015);
  CHECK(loop.outputs().back().dispatch == Dispatch::Send);
  loop.head_state_on = true;
  run_until(loop, 1.2);
  CHECK(loop.outputs().back().mode == ControlMode::Stabilise);
  CHECK(find_event(loop, EventKind::FaultCleared, 1.1, {}, Fault::HeadStateStale));
}

TEST_CASE("tracking lost: fixate falls back to stabilise, then to hold after lost_to_hold_s, and fixates again when the "
          "target returns",
          "[head][watchdog]") {
  HeadControllerOptions o;
  ClosedLoop loop = make_loop(o);
  loop.controller().request(ControlMode::Fixate);
  loop.tracker_on = true;
  run_until(loop, 2.0);
  CHECK(loop.outputs().back().mode == ControlMode::Fixate);
  loop.tracker_on = false;
  run_until(loop, 2.0 + 0.5);
  auto stab = find_event(loop, EventKind::ModeChanged, 2.0, ControlMode::Stabilise);
  REQUIRE(stab);
  CHECK(stab->reason == ModeReason::TrackingLost);
  // The last result arrives 25 ms after its exposure; the timeout counts from its arrival.
  CHECK(stab->t_s == Approx(2.0 + 0.025 + 0.25).margin(0.04));
  run_until(loop, stab->t_s + 2.1);
  auto hold = find_event(loop, EventKind::ModeChanged, 2.0, ControlMode::Hold);
  REQUIRE(hold);
  CHECK(hold->reason == ModeReason::TrackingLostLong);
  CHECK(hold->t_s == Approx(stab->t_s + 2.0).margin(0.002));
  const double back_on = loop.t_s();
  loop.tracker_on = true;
  run_until(loop, back_on + 0.1);
  auto fix = find_event(loop, EventKind::ModeChanged, back_on, ControlMode::Fixate);
  REQUIRE(fix);
  CHECK(fix->reason == ModeReason::TrackingRecovered);
  CHECK(fix->t_s <= back_on + 0.025 + 0.002);  // the first result after processing
}

TEST_CASE("park goes to the park angles no faster than the park rate and reports parked", "[head][watchdog]") {
  HeadControllerOptions o;
  o.park_rate_radps = 0.8;
  ClosedLoop loop = make_loop(o, false);
  run_until(loop, 0.5);
  loop.controller().request(ControlMode::Park);
  double peak = 0;
  while (loop.t_s() < 2.5) {
    const ControlOutput& out = loop.tick();
    peak = std::max({peak, std::abs(out.command.pan_rate_radps), std::abs(out.command.tilt_rate_radps)});
  }
  CHECK(peak <= 0.8 + 1e-9);
  auto parked = find_event(loop, EventKind::Parked, 0.5);
  REQUIRE(parked);
  CHECK(std::abs(loop.plant().angles().pan_rad - o.park.pan_rad) < 0.003);
  CHECK(std::abs(loop.plant().angles().tilt_rad - o.park.tilt_rad) < 0.003);
  auto e = find_event(loop, EventKind::ModeChanged, 0.5, ControlMode::Park);
  REQUIRE(e);
  CHECK(e->reason == ModeReason::Requested);
}

TEST_CASE("a stuck joint does not wind up the commanded angle, so it does not lunge when it frees", "[head][watchdog]") {
  HeadControllerOptions o;
  LoopOptions lo;
  lo.target_world = {2.0, 2.0, 0.0};  // 45 deg left: fixation wants to pan far
  ClosedLoop loop = make_loop(o, false, lo);
  loop.controller().request(ControlMode::Fixate);
  loop.tracker_on = true;
  loop.plant().set_stuck_pan(true);
  run_until(loop, 2.0);
  CHECK(loop.controller().counters().following_error_clamped > 0);
  CHECK(std::abs(loop.outputs().back().command.pan_rad - loop.plant().angles().pan_rad) <= o.max_following_error_rad + 0.01);
}

TEST_CASE("every mode change is reported once as an event, with the modes it joins", "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  loop.controller().request(ControlMode::Fixate);
  loop.tracker_on = true;
  for (int i = 0; i < 4000; ++i) {
    const double t = loop.t_s();
    loop.imu_on = !(t > 0.5 && t < 0.7);
    loop.bus_off = t > 1.0 && t < 1.3;
    loop.tracker_on = !(t > 1.6 && t < 2.2);
    loop.head_state_on = !(t > 2.6 && t < 2.8);
    if (i == 3500) loop.controller().request(ControlMode::Park);
    loop.tick();
  }
  int changes = 0;
  ControlMode prev = ControlMode::Startup;
  for (const ControlOutput& out : loop.outputs()) {
    if (out.mode != prev) ++changes;
    prev = out.mode;
  }
  int events = 0;
  ControlMode from = ControlMode::Startup;
  for (const HeadEvent& e : loop.events()) {
    if (e.kind != EventKind::ModeChanged) continue;
    ++events;
    CHECK(e.from == from);
    from = e.to;
  }
  CHECK(changes >= 8);
  CHECK(events == changes);
  CHECK(loop.controller().counters().events_dropped == 0);
}

TEST_CASE("IMU dropout while fixating: hold during the gap, then the target is centred again", "[head][watchdog]") {
  ClosedLoop loop = make_loop();
  loop.controller().request(ControlMode::Fixate);
  loop.tracker_on = true;
  run_until(loop, 1.9);  // a burst starts at 1.7 s: the camera turns with the body while the IMU is gone
  loop.imu_on = false;
  run_until(loop, 2.1);
  CHECK(loop.outputs().back().mode == ControlMode::Hold);
  loop.imu_on = true;
  run_until(loop, 3.0);
  CHECK(loop.outputs().back().mode == ControlMode::Fixate);
  auto back = find_event(loop, EventKind::ModeChanged, 2.1, ControlMode::Fixate);
  REQUIRE(back);
  CHECK(back->reason == ModeReason::Recovered);
  CHECK(loop.target_angle_rad() < 0.002);
}
