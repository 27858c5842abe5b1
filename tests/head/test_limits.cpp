// Limits are never exceeded in the commands, whatever comes in (random and garbage inputs),
// every command is encodable, and the controller is deterministic.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "epichead/firmware_iface/head_command.h"
#include "epichead/head/head_controller.h"
#include "epichead/head/joint_limits.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using epichead::head::testing::require_within_position_and_rate_limits;
using epichead::hw::CanBusState;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A random, often broken, input stream: times that stall, jump or go back, NaN and absurd
// readings, missing inputs, bus states flipping, targets behind the camera, mode requests.
class Garbage {
 public:
  explicit Garbage(std::uint64_t seed) : rng_(seed) {}
  ControlInput next(HeadController& c) {
    ControlInput in;
    const double r = u();
    if (r < 0.02) in.t_s = t_;                       // stalled
    else if (r < 0.03) in.t_s = t_ - 0.01;          // backwards
    else if (r < 0.035) in.t_s = kNaN;
    else if (r < 0.04) in.t_s = (t_ += 0.02);       // late tick
    else in.t_s = (t_ += 0.0005 + 0.002 * u());
    const double tt = std::isfinite(in.t_s) ? in.t_s : t_;
    if (u() < 0.9) in.gyro = GyroReading{tt, Eigen::Vector3d(g(3), g(3), g(3))};
    if (u() < 0.01 && in.gyro) in.gyro->gyro_radps.x() = kNaN;
    if (u() < 0.01 && in.gyro) in.gyro->gyro_radps.y() = 1e9;
    if (u() < 0.9) in.head = JointState{tt, {g(4), g(2)}, g(20), g(20)};
    if (u() < 0.01 && in.head) in.head->angles.pan_rad = kNaN;
    const double b = u();
    in.bus = b < 0.02 ? CanBusState::BusOff : b < 0.05 ? CanBusState::ErrorPassive : CanBusState::ErrorActive;
    if (u() < 0.05) in.target = TargetObservation{tt - 0.05 * u(), Eigen::Vector3d(g(2), g(2), g(3))};
    if (u() < 0.003) in.target = TargetObservation{kNaN, Eigen::Vector3d(kNaN, 0, 1)};
    if (u() < 0.01) c.request(static_cast<ControlMode>(1 + static_cast<int>(u() * 4)));
    return in;
  }

 private:
  double u() { return std::uniform_real_distribution<double>(0, 1)(rng_); }
  double g(double scale) { return std::uniform_real_distribution<double>(-scale, scale)(rng_); }
  std::mt19937_64 rng_;
  double t_ = 0;
};

bool on_grid(double v, double lsb) { return std::abs(v / lsb - std::nearbyint(v / lsb)) < 1e-6; }

}  // namespace

TEST_CASE("no command exceeds a position, rate or acceleration limit under random and garbage inputs",
          "[head][limits]") {
  HeadControllerOptions o;
  // Backlash compensation adds its band crossings to the desired rates: the shaper must still hold.
  const double backlash = GENERATE(0.0, 0.0005, 0.02);
  o.backlash = {backlash, backlash};
  INFO("backlash " << backlash);
  auto created = HeadController::create(o);
  REQUIRE(created);
  HeadController c = std::move(*created);
  Garbage garbage(42);
  double last_t = kNaN;
  ControlOutput prev;
  bool have_prev = false;
  int checked_accel = 0, limited = 0;
  for (int i = 0; i < 100000; ++i) {
    const ControlInput in = garbage.next(c);
    const ControlOutput out = c.step(in);
    const auto& cmd = out.command;
    // Position, rate, grid, encodable.
    require_within_position_and_rate_limits(cmd, o);
    REQUIRE(on_grid(cmd.pan_rate_radps, epichead::firmware_iface::kHeadRateRadpsPerLsb));
    REQUIRE(on_grid(cmd.pan_rad, epichead::firmware_iface::kHeadAngleRadPerLsb));
    REQUIRE(epichead::firmware_iface::encode(cmd).has_value());
    // Acceleration between consecutive ticks, over the time the controller integrated. A
    // restart from the measured state (leaving Startup, bus or head state back) is exempt: the
    // head stopped on its own and the command starts from what it does.
    bool resync = prev.mode == ControlMode::Startup;
    for (int k = 0; k < out.event_count; ++k) {
      const HeadEvent& e = out.events[static_cast<std::size_t>(k)];
      if (e.kind == EventKind::FaultCleared && (e.fault == Fault::BusOff || e.fault == Fault::HeadStateStale)) resync = true;
    }
    double dt = 0;
    if (std::isfinite(in.t_s) && (!std::isfinite(last_t) || in.t_s > last_t)) {
      dt = std::isfinite(last_t) ? std::min(in.t_s - last_t, 5.0 / o.rate_hz) : 0.0;
      last_t = in.t_s;
    }
    if (have_prev && !resync) {
      REQUIRE(std::abs(cmd.pan_rate_radps - prev.command.pan_rate_radps) <= o.pan.accel_max_radps2 * dt + 1e-9);
      REQUIRE(std::abs(cmd.tilt_rate_radps - prev.command.tilt_rate_radps) <= o.tilt.accel_max_radps2 * dt + 1e-9);
      ++checked_accel;
    }
    limited += (out.pan_limits | out.tilt_limits) != 0;
    prev = out;
    have_prev = true;
  }
  const HeadCounters& k = c.counters();
  INFO("accel checks " << checked_accel << ", limited ticks " << limited);
  CHECK(checked_accel > 90000);
  CHECK(limited > 1000);  // the garbage does push against the limits
  CHECK(k.gyro_rejected > 0);
  CHECK(k.head_state_rejected > 0);
  CHECK(k.target_rejected > 0);
  CHECK(k.time_not_advancing > 0);
  CHECK(k.sent + k.withheld == k.steps);
}

TEST_CASE("the shaper brakes before a position limit instead of hitting it at speed", "[head][limits]") {
  const JointLimits l = default_tilt_limits();
  JointCommand c{0.0, 0.0};
  std::uint8_t hits = 0;
  double peak = 0;
  bool braked = false;
  for (int i = 0; i < 2000; ++i) {
    c = shape(l, c, l.rate_max_radps, 1e-3, hits);
    peak = std::max(peak, c.rate_radps);
    braked |= (hits & kLimitBraking) != 0;
    REQUIRE((hits & kLimitPosition) == 0);  // the safety clamp is never needed
    REQUIRE(c.angle_rad <= l.max_rad);
  }
  CHECK(braked);
  CHECK(peak == Approx(l.rate_max_radps));
  CHECK(c.rate_radps == 0);
  CHECK(c.angle_rad == Approx(l.max_rad).margin(0.01));
}

TEST_CASE("the shaper limits rate and acceleration and keeps rates on the wire grid", "[head][limits]") {
  const JointLimits l = default_pan_limits();
  std::uint8_t hits = 0;
  JointCommand c = shape(l, {0.0, 0.0}, 100.0, 1e-3, hits);
  CHECK((hits & kLimitRate) != 0);
  CHECK((hits & kLimitAccel) != 0);
  CHECK(c.rate_radps == Approx(0.06));
  c = shape(l, {0.0, 0.0}, 0.0123, 1e-3, hits);
  CHECK(hits == 0);
  CHECK(c.rate_radps == Approx(0.010));
  CHECK(c.angle_rad == Approx(0.010e-3));
  c = shape(l, {0.0, 0.0}, kNaN, 1e-3, hits);
  CHECK(c.rate_radps == 0);
}

TEST_CASE("options out of range are refused with the field named", "[head][limits]") {
  HeadControllerOptions o;
  o.tilt.max_rad = -1;
  auto r = HeadController::create(o);
  REQUIRE_FALSE(r);
  CHECK(r.error().find("tilt") != std::string::npos);
  o = {};
  o.park.tilt_rad = 2.0;
  r = HeadController::create(o);
  REQUIRE_FALSE(r);
  CHECK(r.error().find("park.tilt_rad") != std::string::npos);
  o = {};
  o.watchdog.imu_timeout_s = kNaN;
  r = HeadController::create(o);
  REQUIRE_FALSE(r);
  CHECK(r.error().find("imu_timeout_s") != std::string::npos);
  o = {};
  o.safe_mode = ControlMode::Fixate;
  CHECK_FALSE(HeadController::create(o));
}

TEST_CASE("limits beyond the wire's range are clipped to it and counted", "[head][limits]") {
  HeadControllerOptions o;
  o.pan = {-4.0, 4.0, 12.0, 1000.0};  // more than int16 angles and int12 rates hold
  o.hold_max_rate_radps = 12.0;
  o.hold_gain_per_s = 1000;
  o.park = {3.9, 0.0};
  o.park_rate_radps = 12.0;
  auto c = HeadController::create(o);
  REQUIRE(c);
  c->request(ControlMode::Park);
  for (int i = 1; i < 3000; ++i) {
    ControlInput in;
    in.t_s = i * 1e-3;
    in.gyro = GyroReading{in.t_s, Eigen::Vector3d::Zero()};
    in.head = JointState{in.t_s, {-3.9, 0.0}, 0, 0};
    const ControlOutput out = c->step(in);
    REQUIRE(std::abs(out.command.pan_rate_radps) <= 10.24);
    REQUIRE(std::abs(out.command.pan_rad) <= 3.2768);
  }
  CHECK(c->counters().encode_clipped > 0);
}

TEST_CASE("the controller is deterministic: the same inputs give bit-identical commands", "[head][limits]") {
  auto run = [] {
    auto c = HeadController::create({});
    REQUIRE(c);
    Garbage garbage(7);
    std::vector<double> trace;
    for (int i = 0; i < 20000; ++i) {
      const ControlOutput out = c->step(garbage.next(*c));
      trace.insert(trace.end(), {out.command.pan_rad, out.command.tilt_rad, out.command.pan_rate_radps,
                                 out.command.tilt_rate_radps, static_cast<double>(out.mode),
                                 static_cast<double>(out.event_count), out.target_error_rad});
    }
    return trace;
  };
  const std::vector<double> a = run(), b = run();
  REQUIRE(a.size() == b.size());
  bool same = true;
  for (std::size_t i = 0; i < a.size(); ++i) same &= (a[i] == b[i]) || (std::isnan(a[i]) && std::isnan(b[i]));
  CHECK(same);
}

TEST_CASE("a decoded HeadState becomes the controller's joint state with its arrival time", "[head][limits]") {
  epichead::firmware_iface::HeadState s;
  s.pan_rad = 0.25;
  s.tilt_rad = -0.125;
  s.pan_rate_radps = 0.5;
  s.tilt_rate_radps = -1.0;
  const JointState j = joint_state_from(s, 12.5);
  CHECK(j.t_s == 12.5);
  CHECK(j.angles.pan_rad == 0.25);
  CHECK(j.angles.tilt_rad == -0.125);
  CHECK(j.pan_rate_radps == 0.5);
  CHECK(j.tilt_rate_radps == -1.0);
}
