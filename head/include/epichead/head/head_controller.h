#pragma once
// The 1 kHz pan/tilt controller as a pure, deterministic step function: the onboard loop (or a
// simulation) gives it, each tick, the time, the newest gyro sample, head state and target
// observation and the bus state; it returns the HeadCommand to send with diagnostics. No I/O,
// no clock, no allocation after create().
//
// Modes (control_mode.h): Stabilise keeps the optical axis still in space: the gyro on the
// camera measures camera rate = body rate + joint rates, so the body rate is the gyro minus
// the measured joint rates mapped through the joint axes, and the joints are commanded to
// cancel it (feed-forward), plus a proportional term on the optical axis' angle from its
// reference (feedback; reference taken at mode entry, kept in the gyro-integrated frame).
// Two joints cancel rotation about the camera's x and y axes (the ones that shift the image)
// only: roll about the optical axis is left as it is. Fixate steers the optical axis toward
// the target direction (carried from its observation time to now with the gyro attitude, and
// extrapolated with its own filtered angular rate), rate-limited, on top of the same
// body-rate cancellation. Hold keeps the joint angles where the joints come to rest; Park goes
// to the park angles at the park rate. Every switch blends the commanded rate linearly from its
// value at the switch to the new mode's over switch_blend_s, and every command passes the
// limit shaper (joint_limits.h), so no command exceeds a position, rate or acceleration limit.
// With the head's gear backlash calibrated (options.backlash), Stabilise and Fixate command the
// motors through its inverse (backlash_compensation.h): the camera-rate laws want output-shaft
// rates, the motor crosses the dead band quickly after a reversal, and the joint rates taken
// off the gyro are the output's.
//
// Watchdog (watchdog.h): ImuStale -> Stabilise/Fixate fall back to Hold; BusOff or
// HeadStateStale -> safe_mode (Hold or Park) and, while bus-off, Dispatch::Withhold; TargetLost
// -> Fixate falls back to Stabilise, and to Hold after lost_to_hold_s. When the fault clears
// the requested mode returns (after a bus-off or stale head state the command restarts from
// the measured joint angles).
#include <array>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "epichead/firmware_iface/head_command.h"
#include "epichead/firmware_iface/head_state.h"
#include "epichead/head/backlash_compensation.h"
#include "epichead/head/backlash_estimate.h"
#include "epichead/head/control_mode.h"
#include "epichead/head/gyro_attitude.h"
#include "epichead/head/head_kinematics.h"
#include "epichead/head/joint_rate_estimate.h"
#include "epichead/head/joint_limits.h"
#include "epichead/head/target_observation.h"
#include "epichead/head/watchdog.h"
#include "epichead/hw/can_bus.h"

namespace epichead::head {

struct HeadControllerOptions {
  HeadMount mount;
  JointLimits pan = default_pan_limits();
  JointLimits tilt = default_tilt_limits();
  // The gear's dead band between motor (encoder) and output (camera) per joint, as measured on
  // the head (docs/head.md); 0 = no compensation. Used in Stabilise and Fixate.
  JointBacklash backlash;
  // Online estimate of the play at direction reversals (encoder against gyro), per joint: it
  // widens the band above when the head has more play than it was told (an uncalibrated or worn
  // gear; backlash_estimate.h).
  BacklashEstimateOptions backlash_estimate;
  double rate_hz = 1000;                  // nominal control rate: a longer tick is integrated as at most 5 nominal ticks
  double stabilise_gain_per_s = 60;       // optical-axis angle error -> camera rate (1/s)
  double fixate_gain_per_s = 5;           // target angle error -> camera rate (1/s)
  double fixate_max_rate_radps = 1.5;     // how fast fixation itself may turn the camera
  double target_rate_filter_s = 0.15;     // low-pass time constant of the target direction's rate
  double target_rate_max_radps = 1.0;     // bound on that rate's feed-forward
  double hold_gain_per_s = 10;            // joint angle error -> joint rate in Hold and Park
  double hold_max_rate_radps = 2.0;
  JointAngles park{0.0, 0.5};             // pan 0, tilt 0.5 rad (about 29 deg) down
  double park_rate_radps = 1.0;
  double park_tolerance_rad = 0.002;      // within this (and slower than 0.01 rad/s): Parked event
  // Body-rate prediction to make up for the delay between a gyro sample and the joints' response
  // (command latency + one tick + motor lag): the feed-forward uses body rate + lead * its
  // low-passed derivative. 0 turns it off (the default: it amplifies gyro noise; set it to the
  // head's measured delay when the motor is slow, see docs/head.md).
  double rate_lead_s = 0;
  double rate_lead_filter_s = 0.004;      // time constant of the derivative's low-pass
  // The joint rates subtracted from the gyro are those of the gyro sample's instant, from the
  // commands sent (joint_rate_estimate.h); the difference is low-passed over body_rate_filter_s,
  // which damps what a timing mismatch between gyro and joints would feed back.
  JointRateEstimateOptions joint_rates;
  double body_rate_filter_s = 0.001;
  double switch_blend_s = 0.05;           // rate blend after a mode switch
  double max_following_error_rad = 0.2;   // commanded angle kept this close to the measured one
  double history_s = 0.5;                 // how old a target observation may be
  ControlMode safe_mode = ControlMode::Hold;  // on BusOff / HeadStateStale: Hold or Park
  WatchdogOptions watchdog;
};

// The newest gyro sample, camera axes, on the program clock (t_s). Bias-corrected if the
// predictor gives a bias estimate; raw is fine (the feedback and vision absorb a small bias).
struct GyroReading {
  double t_s = 0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
};

// The newest measured head state (from firmware_iface::HeadState), program time of arrival.
struct JointState {
  double t_s = 0;
  JointAngles angles;
  double pan_rate_radps = 0, tilt_rate_radps = 0;
};

// A decoded HeadState frame as the controller's input, stamped with its arrival time.
JointState joint_state_from(const firmware_iface::HeadState& state, double receive_t_s);

struct ControlInput {
  double t_s = 0;                              // this tick, program clock
  std::optional<GyroReading> gyro;             // newest sample (a repeat of the previous one is ignored)
  std::optional<JointState> head;              // newest head state (a repeat is ignored)
  hw::CanBusState bus = hw::CanBusState::ErrorActive;
  std::optional<TargetObservation> target;     // a new observation (a repeat of the previous is ignored)
};

// Whether the loop should put the command on the bus.
enum class Dispatch : std::uint8_t {
  Send,
  Withhold,  // Startup (head position unknown) or bus-off; the command is still computed and logged
};

inline constexpr int kMaxEventsPerStep = 8;

struct ControlOutput {
  firmware_iface::HeadCommand command;   // mode Position; angles and rates quantised to the wire grid
  Dispatch dispatch = Dispatch::Withhold;
  ControlMode mode = ControlMode::Startup;  // active
  ControlMode requested = ControlMode::Stabilise;
  Fault faults = Fault::None;
  std::uint8_t pan_limits = 0, tilt_limits = 0;  // LimitHit bits that shaped this tick's command
  double target_error_rad = 0;           // angle optical axis -> target (NaN when no target is known)
  std::array<HeadEvent, kMaxEventsPerStep> events{};
  int event_count = 0;
};

// Everything the controller rejected, clipped or degraded, cumulative.
struct HeadCounters {
  std::uint64_t steps = 0, sent = 0, withheld = 0;
  std::uint64_t time_not_advancing = 0;     // ticks with t_s not after the previous (dt taken as 0)
  std::uint64_t gyro_rejected = 0;          // non-finite gyro samples
  std::uint64_t head_state_rejected = 0;    // non-finite or out-of-order head states
  std::uint64_t target_rejected = 0;        // non-finite, behind the camera, or no attitude at its time
  std::uint64_t rate_limited = 0, accel_limited = 0, braking_limited = 0, position_limited = 0;  // joint-ticks
  std::uint64_t following_error_clamped = 0;  // joint-ticks the commanded angle was pulled toward the measured one
  std::uint64_t backlash_reversals = 0;     // dead-band crossings started by the compensation (both joints)
  std::uint64_t backlash_samples = 0;       // reversals that measured the play (both joints)
  std::uint64_t backlash_samples_rejected = 0;  // crossings too slow or measured outside [0, backlash_estimate.max_rad]
  std::uint64_t encode_clipped = 0;         // command values beyond the wire's range (clipped)
  std::uint64_t events = 0, events_dropped = 0;
};

class HeadController {
 public:
  // Checks the options; the error names the field.
  static std::expected<HeadController, std::string> create(const HeadControllerOptions& options);

  // The mode the caller wants (Startup is not requestable); takes effect at the next step.
  void request(ControlMode mode) { requested_ = mode == ControlMode::Startup ? requested_ : mode; }
  ControlMode requested() const { return requested_; }

  // One control tick.
  ControlOutput step(const ControlInput& in);

  const HeadCounters& counters() const { return counters_; }
  const HeadControllerOptions& options() const { return options_; }
  // inertial_R_cam from the gyro (for diagnostics and tests).
  const GyroAttitude& attitude() const { return attitude_; }
  // The band each joint's compensation uses now: the calibration or, wider, the online estimate.
  JointBacklash backlash_band() const { return {pan_backlash_.band_rad(), tilt_backlash_.band_rad()}; }
  const BacklashEstimator& pan_backlash_estimate() const { return pan_play_; }
  const BacklashEstimator& tilt_backlash_estimate() const { return tilt_play_; }

 private:
  explicit HeadController(const HeadControllerOptions& options);
  struct Resolved {
    ControlMode mode;
    std::optional<ModeReason> fallback;  // the fault that forced it, if any
  };
  Resolved resolve() const;
  void ingest(const ControlInput& in);
  void enter(ControlMode mode, ModeReason reason, double t_s, ControlOutput& out);
  Eigen::Vector2d desired_rates(double t_s, ControlOutput& out);
  // The stages of step(), in order (head_controller.cpp says what each does).
  double advance_clock(double t_s);
  FaultChange supervise(double t_s, bool bus_off, ControlOutput& out);
  void bound_following_error();
  Eigen::Vector2d shape_commands(double t_s, double dt, ControlOutput& out);
  void encode_command(double t_s, Eigen::Vector2d output_rates, ControlOutput& out);
  void command_from_head();
  Eigen::Vector2d camera_rate_law(const Eigen::Vector2d& camera_rate_xy_radps) const;
  void update_body_rate();
  void measure_backlash(bool new_gyro, bool new_head, double gyro_dt_s);
  void emit(ControlOutput& out, const HeadEvent& e);

  HeadControllerOptions options_;
  Watchdog watchdog_;
  GyroAttitude attitude_;
  ControlMode requested_ = ControlMode::Stabilise;
  bool request_changed_ = false;
  ControlMode last_requested_ = ControlMode::Stabilise;
  ControlMode mode_ = ControlMode::Startup;

  bool started_ = false;
  double last_t_s_ = 0;
  bool have_gyro_ = false;
  GyroReading gyro_;
  bool have_head_ = false;
  JointState head_;
  // Body rate in camera axes (gyro minus joint rates), its filtered derivative, and when.
  bool have_body_rate_ = false;
  double body_rate_t_s_ = 0;
  Eigen::Vector3d body_rate_cam_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d body_accel_cam_ = Eigen::Vector3d::Zero();
  JointRateEstimate joint_rates_;
  bool have_target_ = false;
  double target_t_s_ = 0;                 // observation time of the newest valid target
  double target_arrival_t_s_ = 0;         // program time it was given
  Eigen::Vector3d target_dir_ = Eigen::Vector3d::UnitZ();   // inertial, unit
  Eigen::Vector3d target_rate_ = Eigen::Vector3d::Zero();   // inertial rotation rate of the direction
  bool attitude_broken_ = false;          // an IMU gap since the last target: directions do not compare

  JointCommand pan_cmd_, tilt_cmd_;       // the last command (internal, continuous angle)
  BacklashCompensator pan_backlash_, tilt_backlash_;  // where each output sits in its dead band
  BacklashEstimator pan_play_, tilt_play_;            // each joint's play measured online
  Eigen::Vector3d reference_dir_ = Eigen::Vector3d::UnitZ();  // Stabilise: optical axis to hold (inertial)
  JointAngles hold_;                      // Hold target
  bool parked_reported_ = false;
  double blend_t0_s_ = 0;
  Eigen::Vector2d blend_from_ = Eigen::Vector2d::Zero();
  std::uint8_t counter_ = 0;
  HeadCounters counters_;
};

}  // namespace epichead::head
