#pragma once
// Gear backlash compensation for one joint: the dead-band inverse of gimbal and servo control.
// The encoder (HeadState) is on the motor, the camera on the output shaft, and the gear's play
// lets the motor turn backlash_rad after every reversal before the output follows. The
// compensator models the output against the commanded motor angle as a play operator (the
// output rests inside the band and is pushed at either edge) and turns a wanted *output* rate
// into a *motor* rate: the wanted rate itself while the motor pushes on the edge of the wanted
// direction; after a reversal, in addition, the crossing of the band as fast as the joint's
// acceleration allows (the braking curve of joint_limits.h, so the motor reaches the far edge
// at the wanted rate and pushes on from there). The motor rate then goes through the limit
// shaper like any desired rate, so the command obeys the joint's limits. The modelled output's
// rate (zero while the band is crossed) is what the camera gets from the joint: the rate the
// controller subtracts from the gyro (joint_rate_estimate.h).
#include <cstdint>

#include "epichead/head/joint_limits.h"

namespace epichead::head {

// The dead band per joint, a calibrated property of the head (docs/head.md says how to measure
// it). 0: no compensation (the controller is the one without it, bit for bit).
struct JointBacklash {
  double pan_rad = 0;
  double tilt_rad = 0;
};

class BacklashCompensator {
 public:
  // A wanted output rate smaller than this does not count as a reversal (gyro noise around a
  // still camera would swing the motor across the band and back at every sample).
  static constexpr double kReversalRadps = 0.005;

  explicit BacklashCompensator(double backlash_rad = 0) : half_rad_(0.5 * backlash_rad) {}

  bool active() const { return half_rad_ > 0; }
  double band_rad() const { return 2 * half_rad_; }
  // A new width of the band (an online estimate, backlash_estimate.h): the modelled output keeps
  // its place, clamped into the new band around the motor's last command.
  void set_band(double backlash_rad, double motor_angle_rad);
  // Forget where the output sits: it is taken as in the middle of the band around the motor
  // angle, direction unknown (start-up, restart from the measured state).
  void reset(double motor_angle_rad);

  // The motor rate to ask of the shaper so the output moves at output_rate_radps, from the
  // previous motor command.
  double motor_rate(double output_rate_radps, const JointCommand& motor, const JointLimits& limits, double dt_s);
  // The shaped motor command of this tick (over dt_s): moves the modelled output and returns its
  // rate over the tick (the motor's while it pushes, zero inside the band).
  double follow(const JointCommand& motor, double dt_s);
  // The motor command was moved from outside (the following-error bound): the output model
  // keeps inside the band around it, no rate.
  void place(double motor_angle_rad);

  double output_angle_rad() const { return output_rad_; }
  int direction() const { return direction_; }               // +1 / -1: the edge the motor pushes on (0: unknown)
  std::uint64_t reversals() const { return reversals_; }     // band crossings started

 private:
  double half_rad_;
  double output_rad_ = 0;
  int direction_ = 0;
  double last_output_rate_radps_ = 0;
  std::uint64_t reversals_ = 0;
};

}  // namespace epichead::head
