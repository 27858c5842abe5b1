#include "epichead/fusion/pose_update.h"

#include <limits>

#include "epichead/geometry/se3.h"
#include "kalman_update.h"

namespace epichead::fusion {

PoseUpdateResult update_pose(NavState& x, ErrorCovariance& P, const Eigen::Isometry3d& measured_cam_T_obj,
                             const Matrix6d& cov, double gate_chi2) {
  // measured = exp(n) exp(xi) estimate, so log(measured * estimate^-1) ~ xi + n = H dx + n.
  const Vector6d r = geometry::se3_log(measured_cam_T_obj * x.cam_T_obj().inverse());
  ErrorVector dx;
  PoseUpdateResult result;
  result.mahalanobis2 = detail::kalman_update<err::dim>(P, pose_jacobian(x), r, cov, gate_chi2, dx, result.applied);
  if (result.applied) inject(x, dx);
  return result;
}

}  // namespace epichead::fusion
