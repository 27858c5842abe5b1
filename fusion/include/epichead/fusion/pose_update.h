#pragma once
// The vision update: a measured cam_T_obj with the covariance of its left perturbation
// (translation, rotation), exactly what vision::PoseEstimator returns. Mahalanobis-gated.
#include "epichead/geometry/se3.h"
#include "epichead/fusion/nav_state.h"

namespace epichead::fusion {

using geometry::Matrix6d;
using geometry::Vector6d;

struct PoseUpdateResult {
  bool applied = false;     // false: gated (state untouched)
  double mahalanobis2 = 0;  // r' S^-1 r, the normalised innovation squared (chi-square, 6 dof)
};

// Innovation r = se3_log(measured * expected^-1), expected = measured_cam_T_obj(x) (the state's
// pose with its vision error); applied when r' S^-1 r <= gate_chi2. Joseph-form covariance
// update. `cov` is the pose's own noise, the part the vision error in the state does not carry;
// symmetric positive definite (checked by the caller).
// gate_widening (vision's convention, positive semi-definite) is added to S for the gate alone:
// the IMU filter gates a pose against its whole covariance while its vision error state carries
// the correlated part. The reported NIS is the update's own, without it.
PoseUpdateResult update_pose(NavState& x, ErrorCovariance& P, const Eigen::Isometry3d& measured_cam_T_obj,
                             const Matrix6d& cov, double gate_chi2, const Matrix6d& gate_widening = Matrix6d::Zero());

}  // namespace epichead::fusion
