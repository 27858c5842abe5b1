#pragma once
// What a motion model offers the Predictor: start at a vision pose, take later poses through the
// gated update, and give the pose at any time. The IMU filter (imu_filter.h) and the
// constant-velocity filter (constant_velocity.h) implement it, so the Predictor's start-up,
// gating, re-initialisation and counting are written once for both. One virtual call per vision
// pose or prediction, not per sample.
#include <optional>

#include <Eigen/Geometry>

#include "epichead/fusion/pose_prediction.h"
#include "epichead/fusion/pose_update.h"

namespace epichead::fusion {

class PoseFilter {
 public:
  virtual ~PoseFilter() = default;

  // Starts (again) at the pose at t_s, covariance of its left perturbation cov (symmetric,
  // positive definite). False when it cannot start there (the IMU filter: no accelerometer
  // reading before t_s); the filter is then unchanged.
  virtual bool initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) = 0;
  // The gated update with the pose at t_s > update_t_s(); empty when the filter keeps no state
  // at t_s (older than its history). A gated pose leaves the filter as it was.
  virtual std::optional<PoseUpdateResult> update(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov,
                                                 double gate_chi2) = 0;
  // The pose at t_s; empty when there is no state to predict it from.
  virtual std::optional<PosePrediction> predict(double t_s) const = 0;
  // Exposure time of the last initialising or applied pose.
  virtual double update_t_s() const = 0;
  // Forgets the state: nothing is predicted until the next initialise().
  virtual void reset() = 0;

 protected:
  PoseFilter() = default;
  PoseFilter(const PoseFilter&) = default;
  PoseFilter(PoseFilter&&) = default;
  PoseFilter& operator=(const PoseFilter&) = default;
  PoseFilter& operator=(PoseFilter&&) = default;
};

}  // namespace epichead::fusion
