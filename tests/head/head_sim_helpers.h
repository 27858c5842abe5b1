#pragma once
// A small body + head simulation for the head tests: a walking-robot-like body (angular-rate
// bursts at every step, as sim/trajectory.h draws them), pan/tilt joints with a first-order
// motor lag, a rate limit, an optional stuck joint and command latency, optional gear backlash
// (the output shaft, which carries the camera, rests inside a dead band until the motor pushes
// it at either edge, as sim/sim_head_node.cpp does; the head state shows the motor), and the
// camera-mounted gyro. The controller runs at 1 kHz; the plant integrates at 10 kHz.
#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "epichead/head/head_controller.h"

namespace epichead::head::testing {

struct BodyBurst {
  double t0_s = 0, duration_s = 0.25;
  Eigen::Vector3d axis_body = Eigen::Vector3d::UnitY();
  double peak_rate_radps = 0;
};

// Bursts every step_period_s with axis (cos phi, sin phi, u(-0.3, 0.3)) and peak 30..80 deg/s.
std::vector<BodyBurst> walking_bursts(double duration_s, std::uint64_t seed, double jerk = 1.0);
// Body angular rate (body axes) at t_s: out-and-back bursts (the angle returns to zero).
Eigen::Vector3d body_rate_radps(const std::vector<BodyBurst>& bursts, double t_s);

struct PlantOptions {
  double motor_lag_s = 0.002;       // first-order lag of the joint rate to its reference
  double position_gain_per_s = 50;  // the head's position loop: rate ref = cmd rate + k (cmd angle - angle)
  double motor_rate_max_radps = 8;
  double command_latency_s = 0.0005;
  double backlash_rad = 0;          // gear dead band between motor (encoder) and output (camera), per joint
  double gyro_noise_radps = 0;      // white, per sample (1 kHz)
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  std::uint64_t seed = 7;
};

class HeadPlant {
 public:
  HeadPlant(const HeadMount& mount, const PlantOptions& options, std::vector<BodyBurst> bursts, JointAngles start);

  // Advances the plant over [t, t + dt] with the commands received so far.
  void advance_to(double t_s);
  // A command sent now reaches the motors after the latency.
  void send(double t_s, const firmware_iface::HeadCommand& command);

  GyroReading gyro(double t_s);               // the gyro now (camera axes, with noise and bias)
  JointState head_state(double t_s) const;    // the motor side (encoder), quantised like the wire
  Eigen::Vector3d true_camera_rate() const { return camera_rate_; }
  Eigen::Quaterniond world_R_cam() const;
  const Eigen::Quaterniond& world_R_body() const { return world_R_body_; }
  JointAngles angles() const { return q_out_; }       // output side: where the camera points
  JointAngles motor_angles() const { return q_; }     // motor side: what the encoder measures
  Eigen::Vector2d joint_rates() const { return qd_out_; }
  void set_stuck_pan(bool stuck) { stuck_pan_ = stuck; }

 private:
  HeadMount mount_;
  PlantOptions options_;
  std::vector<BodyBurst> bursts_;
  double t_s_ = 0;
  Eigen::Quaterniond world_R_body_ = Eigen::Quaterniond::Identity();
  JointAngles q_;                                      // motor
  Eigen::Vector2d qd_ = Eigen::Vector2d::Zero();
  JointAngles q_out_;                                  // output (camera); q_ without backlash
  Eigen::Vector2d qd_out_ = Eigen::Vector2d::Zero();
  Eigen::Vector3d camera_rate_ = Eigen::Vector3d::Zero();
  struct Pending { double apply_t_s; firmware_iface::HeadCommand command; };
  std::deque<Pending> pending_;
  std::optional<firmware_iface::HeadCommand> active_;
  bool stuck_pan_ = false;
  std::mt19937_64 rng_;
};

// The controller closed around the plant at 1 kHz, with switches for the watchdog's faults and
// a tracker that reports the target every frame after a processing delay.
struct LoopOptions {
  double frame_period_s = 1.0 / 30;
  double processing_s = 0.025;     // exposure -> tracker result available
  double target_noise_rad = 0;     // per-frame direction noise of the tracker
  Eigen::Vector3d target_world = Eigen::Vector3d(4, 0, 0.4);  // at t = 0, world = body frame at the start
  Eigen::Vector3d target_velocity_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d target_sway_m = Eigen::Vector3d::Zero();  // and to and fro by this much (sine)
  double target_sway_period_s = 2.0;
  bool stamp_at_arrival = false;   // give the tracker's result the arrival time instead of the exposure time (wrong)
};

class ClosedLoop {
 public:
  ClosedLoop(HeadController controller, HeadPlant plant, LoopOptions options = {});

  // One 1 ms tick: plant to t, inputs (unless switched off), controller step, send.
  const ControlOutput& tick();
  double t_s() const { return t_s_; }
  HeadController& controller() { return controller_; }
  HeadPlant& plant() { return plant_; }
  const std::vector<HeadEvent>& events() const { return events_; }
  const std::vector<ControlOutput>& outputs() const { return outputs_; }

  bool imu_on = true, head_state_on = true, bus_off = false, tracker_on = false;

  // The target in the camera now (true geometry), and its angle from the optical axis.
  Eigen::Vector3d target_cam() const;
  double target_angle_rad() const;

 private:
  HeadController controller_;
  HeadPlant plant_;
  LoopOptions options_;
  double t_s_ = 0;
  double next_exposure_s_ = 0;
  struct Frame { double exposure_s; Eigen::Vector3d target_cam; };
  std::deque<Frame> in_processing_;
  std::vector<HeadEvent> events_;
  std::vector<ControlOutput> outputs_;
  std::mt19937_64 rng_{99};
};

// REQUIREs a command's joint angles within the position limits and its rates within the rate
// limits of the controller's options (the checks every limits test starts with).
void require_within_position_and_rate_limits(const firmware_iface::HeadCommand& command, const HeadControllerOptions& o);

// The camera's x/y (image-shifting) and total angular-rate RMS of a run.
struct RateRms {
  double xy_radps = 0, all_radps = 0;
};
// `seconds` of walking bursts (seed) on a head with plant options `plant`, 1 kHz ticks: the
// controller built from `o` in Stabilise, or (stabilise false) no commands at all, the head
// holding still. Returns the camera's true rate RMS over every tick.
RateRms camera_rate_rms(const HeadControllerOptions& o, const PlantOptions& plant, double seconds, std::uint64_t seed,
                        bool stabilise);

}  // namespace epichead::head::testing
