#pragma once
// The covariances a consumer of tracked poses feeds to a filter (the fusion predictor in
// `epichead track` and in the onboard loop), in one place so that both agree.
// Order: the pose estimator's left perturbation, translation (m) then rotation (rad).
#include <Eigen/Core>

namespace epichead::vision {

// The pose estimator's covariance assumes independent edgels; neighbouring edgels of one
// blurred edge are not, and the model's own errors move all of a feature's edgels together:
// scale it by this before fusing. Chosen on the development seeds (docs/results.md) for the
// vision NIS: 10 (with the estimator's old 1-px noise floor) gave NIS medians of 0.05-0.3, ~100x
// too low; 3 with the 0.25-px floor gives 0.3-3.7 with the box_clutter blur and success
// unchanged, and a tighter covariance made the bowl's poses overconfident (NIS median 68).
inline constexpr double kTrackedPoseCovarianceInflation = 3.0;

// A starting pose given by hand or by init.csv: 1 cm and 1 degree (1-sigma per axis).
inline Eigen::Matrix<double, 6, 6> initial_pose_covariance() {
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Zero();
  constexpr double t_m = 0.01, r_rad = 0.0174533;
  c.diagonal() << t_m * t_m, t_m * t_m, t_m * t_m, r_rad * r_rad, r_rad * r_rad, r_rad * r_rad;
  return c;
}

}  // namespace epichead::vision
