#pragma once
// How the simulated pan/tilt head's firmware and motors move the joints (scenario keys
// head_time_constant_s, head_rate_limit_radps, head_accel_limit_radps2, head_backlash_rad,
// head_friction_radps2, head_servo_rate_hz,
// head_state_rate_hz, head_command_timeout_s). Defaults: a small geared servo head whose
// physical limits lie above the controller's own (head/joint_limits.h: 6 rad/s, 60 rad/s^2,
// pan +-170 deg, tilt +-60 deg), so the controller's limits are the ones that act.
namespace epichead::sim {

enum class Joint { pan, tilt };

struct HeadDynamics {
  double servo_rate_hz = 10000;       // the firmware's servo loop (the simulation's step)
  double time_constant_s = 0.02;      // angle error decays with this lag (position loop 50/s)
  double rate_limit_radps = 8;        // motor speed limit
  double accel_limit_radps2 = 200;    // motor torque limit, as an acceleration
  double backlash_rad = 0.0005;       // gear dead band: output lags the motor this much on reversal
  double friction_radps2 = 0;         // Coulomb friction as a deceleration against the motion (stiction at rest)
  double pan_min_rad = -3.0, pan_max_rad = 3.0;    // end stops
  double tilt_min_rad = -1.1, tilt_max_rad = 1.1;
  double state_rate_hz = 200;         // HeadState frames
  double status_rate_hz = 50;         // HeadStatus frames (currents, faults)
  double heartbeat_rate_hz = 1;       // Heartbeat frames (both nodes)
  double command_timeout_s = 0.1;     // no HeadCommand this long: SafeStop + command-timeout fault
  double current_a_per_radps2 = 0.005;  // motor current ~ joint acceleration (inertia / torque constant)
  double stall_current_a = 3.0;       // a blocked joint draws this (and reports over-current)
};

}  // namespace epichead::sim
