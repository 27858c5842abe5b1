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
  double mahalanobis2 = 0;  // r' S^-1 r, the normalised innovation squared (chi-square, `dims` dof)
  int dims = 6;             // 5 when the pose has a direction vision does not measure (free_direction.h)
};

// Innovation r = se3_log(measured * estimate^-1); applied when r' S^-1 r <= gate_chi2. A pose with
// a free direction (free_direction.h) is compared in the five others only.
// Joseph-form covariance update. `cov` must be symmetric positive definite (checked by the caller).
PoseUpdateResult update_pose(NavState& x, ErrorCovariance& P, const Eigen::Isometry3d& measured_cam_T_obj,
                             const Matrix6d& cov, double gate_chi2);

}  // namespace epichead::fusion
