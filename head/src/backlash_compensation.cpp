#include "epichead/head/backlash_compensation.h"

#include <algorithm>
#include <cmath>

namespace epichead::head {

void BacklashCompensator::reset(double motor_angle_rad) {
  output_rad_ = motor_angle_rad;
  direction_ = 0;
  last_output_rate_radps_ = 0;
}

void BacklashCompensator::set_band(double backlash_rad, double motor_angle_rad) {
  const double half = 0.5 * std::max(0.0, backlash_rad);
  if (half == half_rad_) return;
  // Off until now: the output was modelled as moving with the motor.
  if (!active()) reset(motor_angle_rad);
  half_rad_ = half;
  place(motor_angle_rad);
}

void BacklashCompensator::place(double motor_angle_rad) {
  output_rad_ = std::clamp(output_rad_, motor_angle_rad - half_rad_, motor_angle_rad + half_rad_);
}

double BacklashCompensator::motor_rate(double output_rate_radps, const JointCommand& motor, const JointLimits& limits,
                                       double dt_s) {
  const double v = output_rate_radps;
  if (!active() || !std::isfinite(v)) return v;
  const int wanted = v > kReversalRadps ? 1 : v < -kReversalRadps ? -1 : direction_;
  if (direction_ != 0 && wanted != direction_) ++reversals_;
  direction_ = wanted;
  if (direction_ == 0) return v;
  // How far the motor still is from the edge it must push on.
  const double gap_rad = (output_rad_ + direction_ * half_rad_ - motor.angle_rad) * direction_;
  if (gap_rad <= 0) return v;
  // Toward the edge at the speed from which the motor, decelerating at the joint's limit,
  // arrives there at the wanted rate: v_edge^2 + 2 a gap, on the discrete braking curve.
  const double v_edge = std::max(0.0, v * direction_);
  const double a = limits.accel_max_radps2;
  const double speed = std::max(v_edge, braking_rate_radps(gap_rad + v_edge * v_edge / (2 * a), a, std::max(dt_s, 0.0)));
  return direction_ * speed;
}

double BacklashCompensator::follow(const JointCommand& motor, double dt_s) {
  if (!active()) return motor.rate_radps;
  if (!(dt_s > 0)) return last_output_rate_radps_;  // no time passed: nothing moved
  const double before = output_rad_;
  place(motor.angle_rad);
  last_output_rate_radps_ = (output_rad_ - before) / dt_s;
  return last_output_rate_radps_;
}

}  // namespace epichead::head
