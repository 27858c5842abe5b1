#pragma once
// The IMU on the camera mount: a 3-axis gyro and accelerometer rigidly attached to the camera,
// reporting in the camera frame (rad/s, and specific force a - g in m/s^2), computed from the
// true motion, with white noise, bias random walk, scale-factor error, saturation, dropouts,
// and its own clock: device time = offset + (1 + drift) * true time.
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "epichead/sim/trajectory.h"

namespace epichead::sim {

constexpr double standard_gravity_mps2 = 9.80665;
// Gravity in the world frame (z up).
inline Eigen::Vector3d gravity_world() { return {0, 0, -standard_gravity_mps2}; }

struct ImuParams {
  double rate_hz = 1000;                     // nominal rate on the device clock
  double gyro_noise_radps_rthz = 0;          // white noise density
  double accel_noise_mps2_rthz = 0;
  double gyro_bias_radps = 0;                // standard deviation of the initial bias, per axis
  double accel_bias_mps2 = 0;
  double gyro_bias_walk_radps_rths = 0;      // bias random walk (rad/s per sqrt(s))
  double accel_bias_walk_mps2_rths = 0;
  double gyro_scale_error = 0;               // standard deviation of the per-axis scale error (fraction)
  double accel_scale_error = 0;
  double gyro_range_radps = std::numeric_limits<double>::infinity();   // saturation
  double accel_range_mps2 = std::numeric_limits<double>::infinity();
  double dropouts_per_s = 0;                 // mean rate of dropout starts
  double dropout_s = 0.02;                   // length of one dropout
  double clock_offset_s = 0;                 // device time at true time 0
  double clock_drift = 0;                    // device clock rate error (50e-6 = 50 ppm fast)
};

// One sample: the true values and the measurement, both in the camera frame.
struct ImuSample {
  double t_true_s = 0;    // on the camera (true) clock
  double t_device_s = 0;  // the IMU's own time stamp, what imu.csv holds
  Eigen::Vector3d gyro_true_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_true_mps2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
  bool dropped = false;   // lost on the way: not written to imu.csv
};

// The errors drawn for a run, kept so tests and the truth file can see them.
struct ImuRun {
  std::vector<ImuSample> samples;
  Eigen::Vector3d gyro_scale = Eigen::Vector3d::Ones(), accel_scale = Eigen::Vector3d::Ones();
  Eigen::Vector3d gyro_bias0_radps = Eigen::Vector3d::Zero(), accel_bias0_mps2 = Eigen::Vector3d::Zero();
  int dropped = 0, saturated = 0;  // samples lost, samples with any axis clipped
};

// Exact gyro and specific force of a frame (in that frame) from its motion in the world.
void true_imu(const Kinematics& world_T_imu, Eigen::Vector3d& gyro_radps, Eigen::Vector3d& accel_mps2);

// Samples the IMU on device ticks k / rate_hz whose true time lies in [t0_s, t1_s].
// Deterministic for a seed.
ImuRun simulate_imu(const ImuParams& params, std::uint64_t seed,
                    const std::function<Kinematics(double t_s)>& world_T_imu, double t0_s, double t1_s);

}  // namespace epichead::sim
