#pragma once
// Body trajectories with exact derivatives: the walking robot, the wheeled robot and hand-held
// motion. Every trajectory is built from C-infinity or C3 analytic pieces (sines, sin^4 bumps
// and their closed-form integrals), so the IMU values computed from it are exact, not finite
// differences. World frame: z up, gravity along -z. Body frame: x forward, y left, z up.
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

namespace epichead::sim {

// Pose and motion of a frame relative to a parent frame, all vectors in parent coordinates.
struct Kinematics {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // parent_T_frame
  Eigen::Vector3d omega_radps = Eigen::Vector3d::Zero();   // angular velocity of the frame
  Eigen::Vector3d alpha_radps2 = Eigen::Vector3d::Zero();  // angular acceleration
  Eigen::Vector3d vel_mps = Eigen::Vector3d::Zero();       // velocity of the frame origin
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();    // acceleration of the frame origin
};

// a_T_c from a_T_b (motion of b in a) and b_T_c (motion of c relative to b, in b):
// the rigid-body transport rules, including centripetal and Coriolis terms.
Kinematics compose(const Kinematics& a_T_b, const Kinematics& b_T_c);
// A fixed transform (no motion).
Kinematics fixed_motion(const Eigen::Isometry3d& a_T_b);
// Rotation about a fixed unit axis by angle(t), with its first and second time derivatives.
Kinematics rotation_about(const Eigen::Vector3d& axis, double angle_rad, double rate_radps, double accel_radps2);

// An out-and-back rotation about a fixed body axis: angle = a * sin^4(pi tau), tau = (t - t0)/T.
// sin^4 keeps the motion C3 where the burst starts and ends.
struct Burst {
  double t0_s = 0;
  double duration_s = 0.25;
  Eigen::Vector3d axis_body = Eigen::Vector3d::UnitY();  // unit
  double peak_rate_radps = 0;  // largest |angular rate| during the burst
};

// A turn about world z that stays: angle follows the integral of sin^4, peak rate at mid-turn.
struct Turn {
  double t0_s = 0;
  double angle_rad = 0;
  double peak_rate_radps = 1;  // sets the duration: T = (8/3) angle / peak rate
};

// Pneumatic walking robot: advances in surges (one per step), and at every step gets a brief
// angular-rate burst and a vertical dip. `jerk` scales burst rates and the dip.
struct WalkingParams {
  Eigen::Vector3d start_world{2.0, 0.0, 0.0};  // body origin at t = 0
  double heading_rad = 3.14159265358979;       // direction of travel, about world z from x
  double speed_mps = 0.03;                     // mean advance
  double surge = 0.8;                          // 0: uniform advance; 1: stops between steps
  double step_period_s = 1.4;
  double first_step_s = 0.3;
  double burst_min_degps = 30, burst_max_degps = 80;  // per-step peak rate range at jerk 1
  double burst_s = 0.25;                              // burst duration
  double bob_m = 0.006;                               // vertical dip per step at jerk 1
  double bob_s = 0.35;                                // dip duration
  double jerk = 1.0;
  std::uint64_t seed = 1;  // draws each step's burst axis and peak
};

// Wheeled robot: a smooth straight drive (start and stop with zero acceleration) plus a sudden
// turn of the body.
struct WheeledParams {
  Eigen::Vector3d start_world{3.0, 0.0, 0.0};
  double heading_rad = 3.14159265358979;  // body x direction at t = 0
  double drive_heading_rad = 3.14159265358979;  // direction of travel
  double distance_m = 2.0;
  double drive_start_s = 0.0, drive_duration_s = 10.0;
  double drive_turn_rad = 0;  // heading change spread over the drive like the distance (gentle steering)
  Turn turn;  // the sudden pan
};

// Hand-held camera: smooth sway (sums of sines with seeded phases and frequencies) about a
// viewpoint, plus optional quick shakes. `jerk` scales the shakes' peak rates (the sweep of
// trackable speed, tools/jerk_sweep.sh); the sway stays as it is.
struct HandheldParams {
  Eigen::Vector3d start_world{0.8, 0.0, 0.3};
  double heading_rad = 3.14159265358979;
  double sway_m = 0.03;      // position amplitude per axis
  double sway_deg = 3.0;     // angle amplitude per axis
  double sway_hz = 0.3;      // base frequency
  std::vector<Burst> shakes; // added quick rotations (peak rates at jerk 1)
  double jerk = 1.0;
  std::uint64_t seed = 1;
};

// A body trajectory: world_T_body and its derivatives at any time (defined for all t).
class Trajectory {
 public:
  static Trajectory walking(const WalkingParams& p);
  static Trajectory wheeled(const WheeledParams& p);
  static Trajectory handheld(const HandheldParams& p);

  Kinematics at(double t_s) const;  // world_T_body

 private:
  enum class Kind { walking, wheeled, handheld };
  Kind kind_ = Kind::walking;
  WalkingParams walk_;
  WheeledParams wheel_;
  HandheldParams hand_;
  std::vector<Burst> bursts_;  // hand-held shakes, sorted by start (walking bursts are drawn per step)
  // Hand-held sway: per axis (x, y, z, yaw, pitch, roll) three sines: amplitude, rad/s, phase.
  struct Sine { double amp = 0, w_radps = 0, phase_rad = 0; };
  std::vector<Sine> sway_[6];
};

// Largest |body angular rate| over [t0, t1], sampled every dt (deg/s), for summaries and tests.
double peak_angular_rate_degps(const Trajectory& traj, double t0_s, double t1_s, double dt_s = 1e-3);

}  // namespace epichead::sim
