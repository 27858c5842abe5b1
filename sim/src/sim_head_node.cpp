#include "epichead/sim/sim_head_node.h"

#include <algorithm>
#include <cmath>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/head_state.h"
#include "epichead/firmware_iface/head_status.h"
#include "epichead/firmware_iface/heartbeat.h"
#include "node_heartbeat.h"

namespace epichead::sim {
namespace {

// The acceleration left of the drive's `accel` after Coulomb friction `f` (both rad/s^2): taken
// off against the motion; a moving joint that friction alone would turn round stops instead, and
// a joint at rest stays until the drive exceeds the friction (stiction).
double with_friction(double rate, double accel, double f, double dt_s) {
  if (rate == 0) return std::abs(accel) <= f ? 0.0 : accel - std::copysign(f, accel);
  const double a = accel - std::copysign(f, rate);
  const bool reverses = (rate > 0) != (rate + a * dt_s > 0);
  return reverses && std::abs(accel) <= f ? -rate / dt_s : a;
}

namespace fw = firmware_iface;

void advance(JointMotion& m, double h) {
  m.angle_rad += m.rate_radps * h + 0.5 * m.accel_radps2 * h * h;
  m.rate_radps += m.accel_radps2 * h;
}

// A desired rate below this counts as "hold still" (no stall current against a stuck joint).
constexpr double kStillRadps = 1e-3;
constexpr int kTemperatureDegc = 35;

}  // namespace

HeadAngles output_angles_at(const HeadTick& tick, double t_s) {
  const double h = t_s - tick.t_s;
  HeadAngles a;
  a.pan_rad = tick.pan_out.angle_rad + tick.pan_out.rate_radps * h + 0.5 * tick.pan_out.accel_radps2 * h * h;
  a.tilt_rad = tick.tilt_out.angle_rad + tick.tilt_out.rate_radps * h + 0.5 * tick.tilt_out.accel_radps2 * h * h;
  a.pan_rate_radps = tick.pan_out.rate_radps + tick.pan_out.accel_radps2 * h;
  a.tilt_rate_radps = tick.tilt_out.rate_radps + tick.tilt_out.accel_radps2 * h;
  a.pan_accel_radps2 = tick.pan_out.accel_radps2;
  a.tilt_accel_radps2 = tick.tilt_out.accel_radps2;
  return a;
}

SimHeadNode::SimHeadNode(const HeadDynamics& dynamics, double pan_rad, double tilt_rad)
    : dyn_(dynamics), dt_s_(1.0 / dynamics.servo_rate_hz) {
  tick_.pan_motor.angle_rad = tick_.pan_out.angle_rad = pan_rad;
  tick_.tilt_motor.angle_rad = tick_.tilt_out.angle_rad = tilt_rad;
}

void SimHeadNode::deliver(const fw::CanFrame& frame, double t_s) {
  if (frame.id != fw::kIdHeadCommand || frame.extended()) return;
  auto command = fw::decode_head_command(frame);
  if (!command) {
    ++counters_.commands_rejected;
    return;
  }
  ++counters_.commands;
  command_ = *command;
  command_t_s_ = t_s;
  have_command_ = true;
  mode_ = command_.mode;
  faults_ &= static_cast<std::uint16_t>(~fw::kFaultCommandTimeout);
}

void SimHeadNode::tick(double t_s, bool pan_stuck, bool tilt_stuck) {
  if (started_) {
    const double h = t_s - tick_.t_s;
    for (JointMotion* m : {&tick_.pan_motor, &tick_.tilt_motor, &tick_.pan_out, &tick_.tilt_out}) advance(*m, h);
  }
  started_ = true;
  tick_.t_s = t_s;
  ++counters_.ticks;
  const bool moving_mode = mode_ == fw::HeadMode::Position || mode_ == fw::HeadMode::Rate;
  if (have_command_ && moving_mode && t_s - command_t_s_ > dyn_.command_timeout_s) {
    mode_ = fw::HeadMode::SafeStop;
    faults_ |= fw::kFaultCommandTimeout;
    ++counters_.command_timeouts;
  }
  plan_joint(0, t_s, pan_stuck, tick_.pan_motor, tick_.pan_out);
  plan_joint(1, t_s, tilt_stuck, tick_.tilt_motor, tick_.tilt_out);
}

void SimHeadNode::plan_joint(int j, double t_s, bool stuck, JointMotion& motor, JointMotion& out) {
  const std::uint16_t over_current = j == 0 ? fw::kFaultPanOverCurrent : fw::kFaultTiltOverCurrent;
  const std::uint16_t at_limit = j == 0 ? fw::kFaultPanLimit : fw::kFaultTiltLimit;
  const double lo = j == 0 ? dyn_.pan_min_rad : dyn_.tilt_min_rad;
  const double hi = j == 0 ? dyn_.pan_max_rad : dyn_.tilt_max_rad;
  const double cmd_angle = j == 0 ? command_.pan_rad : command_.tilt_rad;
  const double cmd_rate = j == 0 ? command_.pan_rate_radps : command_.tilt_rate_radps;

  double desired = 0;
  if (mode_ == fw::HeadMode::Position) {
    // The command's rate carries its angle forward until the next command arrives.
    const double reference = cmd_angle + cmd_rate * std::min(t_s - command_t_s_, dyn_.command_timeout_s);
    desired = cmd_rate + (reference - motor.angle_rad) / dyn_.time_constant_s;
  } else if (mode_ == fw::HeadMode::Rate) {
    desired = cmd_rate;
  }
  desired = std::clamp(desired, -dyn_.rate_limit_radps, dyn_.rate_limit_radps);

  if (stuck) {
    motor.rate_radps = motor.accel_radps2 = out.rate_radps = out.accel_radps2 = 0;
    const bool pushing = std::abs(desired) > kStillRadps;
    current_a_[j] = pushing ? std::copysign(dyn_.stall_current_a, desired) : 0.0;
    faults_ = pushing ? (faults_ | over_current) : (faults_ & static_cast<std::uint16_t>(~over_current));
    return;
  }
  faults_ &= static_cast<std::uint16_t>(~over_current);

  double accel = std::clamp((desired - motor.rate_radps) / dt_s_, -dyn_.accel_limit_radps2, dyn_.accel_limit_radps2);
  if (dyn_.friction_radps2 > 0) accel = with_friction(motor.rate_radps, accel, dyn_.friction_radps2, dt_s_);
  const double next_angle = motor.angle_rad + motor.rate_radps * dt_s_ + 0.5 * accel * dt_s_ * dt_s_;
  if ((next_angle > hi && desired >= 0) || (next_angle < lo && desired <= 0)) {
    // The end stop: the joint stops dead there.
    motor.angle_rad = std::clamp(motor.angle_rad, lo, hi);
    motor.rate_radps = 0;
    accel = 0;
    faults_ |= at_limit;
  } else {
    faults_ &= static_cast<std::uint16_t>(~at_limit);
  }
  motor.accel_radps2 = accel;
  current_a_[j] = dyn_.current_a_per_radps2 * accel;

  // The output shaft: inside the dead band it rests; at either edge the motor drives it.
  const double half = 0.5 * dyn_.backlash_rad;
  out.angle_rad = std::clamp(out.angle_rad, motor.angle_rad - half, motor.angle_rad + half);
  const double next_rate = motor.rate_radps + accel * dt_s_;
  // Driven only when the motor moves into the edge for the whole tick; in a tick where it
  // reverses, the output rests (the next tick's clamp corrects the few microradians).
  const bool moving_up = motor.rate_radps >= 0 && next_rate >= 0 && (motor.rate_radps > 0 || next_rate > 0);
  const bool moving_down = motor.rate_radps <= 0 && next_rate <= 0 && (motor.rate_radps < 0 || next_rate < 0);
  // "At the edge" with a tolerance: motor and output advance by the same motion but round
  // differently, and an exact comparison would let the output rest for a tick mid-motion.
  constexpr double kEdgeToleranceRad = 1e-9;
  const bool pushed_up = out.angle_rad <= motor.angle_rad - half + kEdgeToleranceRad && moving_up;
  const bool pushed_down = out.angle_rad >= motor.angle_rad + half - kEdgeToleranceRad && moving_down;
  if (pushed_up || pushed_down) {
    out.angle_rad = motor.angle_rad + (pushed_up ? -half : half);
    out.rate_radps = motor.rate_radps;
    out.accel_radps2 = accel;
  } else {
    out.rate_radps = out.accel_radps2 = 0;
  }
}

fw::CanFrame SimHeadNode::state_frame(double) {
  fw::HeadState s;
  s.counter = state_counter_++ % 16;
  s.mode = mode_;
  s.pan_rad = tick_.pan_motor.angle_rad;
  s.tilt_rad = tick_.tilt_motor.angle_rad;
  s.pan_rate_radps = tick_.pan_motor.rate_radps;
  s.tilt_rate_radps = tick_.tilt_motor.rate_radps;
  auto e = fw::encode(s);
  return e ? e->frame : fw::CanFrame{};
}

fw::CanFrame SimHeadNode::status_frame() {
  fw::HeadStatus s;
  s.pan_current_a = current_a_[0];
  s.tilt_current_a = current_a_[1];
  s.faults = faults_;
  s.counter = status_counter_++;
  s.temperature_degc = kTemperatureDegc;
  auto e = fw::encode(s);
  return e ? e->frame : fw::CanFrame{};
}

fw::CanFrame SimHeadNode::heartbeat_frame(double t_s) {
  return node_heartbeat_frame(fw::kNodeHead, faults_ == 0 ? fw::NodeState::Operational : fw::NodeState::Degraded, t_s);
}

}  // namespace epichead::sim
