#pragma once
// The covariances a consumer of tracked poses feeds to a filter (the fusion predictor in
// `epichead track` and in the onboard loop), in one place so that both agree.
// Order: the pose estimator's left perturbation, translation (m) then rotation (rad).
#include <Eigen/Core>

namespace epichead::vision {

// The pose estimator's covariance assumes independent edgels; neighbouring edgels of one
// blurred edge are not, so it is optimistic by about the number of edgels per line (10 by
// default, ModelTrackerOptions::max_edgels_per_line): scale it by this before fusing.
inline constexpr double kTrackedPoseCovarianceInflation = 10.0;

// A starting pose given by hand or by init.csv: 1 cm and 1 degree (1-sigma per axis).
inline Eigen::Matrix<double, 6, 6> initial_pose_covariance() {
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  constexpr double t_m = 0.01, r_rad = 0.0174533;
  c.diagonal() << t_m * t_m, t_m * t_m, t_m * t_m, r_rad * r_rad, r_rad * r_rad, r_rad * r_rad;
  return c;
}

}  // namespace epichead::vision
