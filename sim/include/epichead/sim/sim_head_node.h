#pragma once
// The simulated pan/tilt head: its firmware decodes HeadCommand frames and servos the two joints;
// it publishes HeadState (motor encoder angles and rates), HeadStatus (currents, fault bits) and
// a Heartbeat. Kinematic convention of head_mount.h: pan about body z, tilt about the pan
// frame's y, positive tilt looks down.
//
// Per joint, every servo tick (1 / servo_rate_hz), from the latched command:
//   Position: reference angle = command angle + command rate * (time since the command), and
//             rate = command rate + (reference - angle) / time_constant   (first-order lag)
//   Rate:     rate = command rate
//   Off, SafeStop, or no command yet: rate = 0 (the joint brakes to rest and holds)
// then the rate is limited to rate_limit and its change to accel_limit per tick, and the motor
// stops at the end stops. The output shaft follows the motor through the gear's backlash: a
// dead band of backlash_rad it must cross after every reversal before the output moves. The
// encoder is on the motor, so HeadState shows the motor; the camera moves with the output.
// No HeadCommand for command_timeout_s: SafeStop with the command-timeout fault until the next
// command. A stuck joint (fault) does not move at all and draws stall current.
#include <cstdint>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/head_command.h"
#include "epichead/firmware_iface/head_mode.h"
#include "epichead/sim/head_dynamics.h"
#include "epichead/sim/head_mount.h"

namespace epichead::sim {

// One joint over one servo tick: the state at the tick's start and the constant acceleration
// during it (angle(t) = angle + rate (t - t0) + accel (t - t0)^2 / 2).
struct JointMotion {
  double angle_rad = 0, rate_radps = 0, accel_radps2 = 0;
};

// Both joints over one servo tick starting at t_s: motor (encoder) side and output (camera) side.
struct HeadTick {
  double t_s = 0;
  JointMotion pan_motor, tilt_motor, pan_out, tilt_out;
};

// The output joints' angles, rates and accelerations at t_s inside (or just past) a tick.
HeadAngles output_angles_at(const HeadTick& tick, double t_s);

struct HeadNodeCounters {
  std::uint64_t commands = 0;           // HeadCommand frames accepted
  std::uint64_t commands_rejected = 0;  // frames with the command id that did not decode
  std::uint64_t command_timeouts = 0;   // times the head went to SafeStop for lack of commands
  std::uint64_t ticks = 0;
};

class SimHeadNode {
 public:
  SimHeadNode(const HeadDynamics& dynamics, double pan_rad, double tilt_rad);

  // A frame from the bus reaches the firmware at t_s (HeadCommand; other ids are ignored). It
  // acts from the next servo tick on.
  void deliver(const firmware_iface::CanFrame& frame, double t_s);
  // The servo tick starting at t_s: completes the previous tick's motion and plans this one.
  // Ticks must come every 1 / servo_rate_hz.
  void tick(double t_s, bool pan_stuck, bool tilt_stuck);

  const HeadTick& current() const { return tick_; }
  firmware_iface::HeadMode mode() const { return mode_; }
  std::uint16_t faults() const { return faults_; }  // firmware_iface::HeadFault bits
  double pan_current_a() const { return current_a_[0]; }
  double tilt_current_a() const { return current_a_[1]; }

  // The frames the head publishes (counters advance per frame sent).
  firmware_iface::CanFrame state_frame(double t_s);
  firmware_iface::CanFrame status_frame();
  firmware_iface::CanFrame heartbeat_frame(double t_s);

  const HeadNodeCounters& counters() const { return counters_; }
  const HeadDynamics& dynamics() const { return dyn_; }

 private:
  // Plans one joint's tick; returns the planned acceleration and sets current and fault bits.
  void plan_joint(int j, double t_s, bool stuck, JointMotion& motor, JointMotion& out);

  HeadDynamics dyn_;
  double dt_s_;
  HeadTick tick_;
  bool started_ = false;
  firmware_iface::HeadMode mode_ = firmware_iface::HeadMode::Off;
  bool have_command_ = false;
  firmware_iface::HeadCommand command_;
  double command_t_s_ = 0;
  std::uint16_t faults_ = 0;
  double current_a_[2] = {0, 0};
  std::uint8_t state_counter_ = 0, status_counter_ = 0;
  HeadNodeCounters counters_;
};

}  // namespace epichead::sim
