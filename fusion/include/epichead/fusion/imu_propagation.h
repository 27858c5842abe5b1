#pragma once
// One IMU step of the error-state filter: the nominal state by the midpoint rule between two
// samples, and the error covariance through the sparse first-order transition (docs/fusion.md).
#include <Eigen/Core>

#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/nav_state.h"

namespace epichead::fusion {

// Continuous-time noise of the IMU model (datasheet densities).
struct ImuNoise {
  double gyro_noise_radps_rthz = 2e-3;
  double accel_noise_mps2_rthz = 2e-2;
  double gyro_bias_walk_radps_rths = 2e-5;
  double accel_bias_walk_mps2_rths = 5e-4;
  double gravity_walk_rad_rths = 0;  // > 0 lets the gravity direction drift (e.g. a tilting object)
};

// Where the IMU sits: orientation in the camera (the lever arm is taken as zero).
struct ImuMount {
  Eigen::Matrix3d cam_R_imu = Eigen::Matrix3d::Identity();
};

// Propagates x and P from s0.t_s to s1.t_s (camera clock, s1.t_s >= s0.t_s) with the raw
// readings at both ends. No allocation.
void propagate(NavState& x, ErrorCovariance& P, const ImuSample& s0, const ImuSample& s1, const ImuMount& mount,
               const ImuNoise& noise);

// The reading at t_s between a and b (linear), or the nearer end outside [a.t_s, b.t_s].
ImuSample interpolate(const ImuSample& a, const ImuSample& b, double t_s);

}  // namespace epichead::fusion
