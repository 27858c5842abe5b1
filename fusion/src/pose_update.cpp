#include "epichead/fusion/pose_update.h"

#include <limits>

#include "epichead/fusion/free_direction.h"
#include "epichead/geometry/se3.h"
#include "kalman_update.h"

namespace epichead::fusion {

PoseUpdateResult update_pose(NavState& x, ErrorCovariance& P, const Eigen::Isometry3d& measured_cam_T_obj,
                             const Matrix6d& cov, double gate_chi2) {
  // measured = exp(n) exp(xi) estimate, so log(measured * estimate^-1) ~ xi + n = H dx + n.
  const Vector6d r = geometry::se3_log(measured_cam_T_obj * x.cam_T_obj().inverse());
  ErrorVector dx;
  PoseUpdateResult result;
  if (const auto free = find_free_direction(cov)) {
    // The five directions vision measures (free_direction.h): the turn it left open is not compared.
    const Eigen::Matrix<double, 6, 5> B = free->measured.leftCols<5>();
    const Eigen::Matrix<double, 5, 1> r5 = B.transpose() * r;
    const Eigen::Matrix<double, 5, err::dim> H5 = B.transpose() * pose_jacobian(x);
    const Eigen::Matrix<double, 5, 5> R5 = free->variances.head<5>().asDiagonal();
    result.mahalanobis2 = detail::kalman_update<err::dim>(P, H5, r5, R5, gate_chi2, dx, result.applied);
    result.dims = 5;
  } else {
    result.mahalanobis2 = detail::kalman_update<err::dim>(P, pose_jacobian(x), r, cov, gate_chi2, dx, result.applied);
  }
  if (result.applied) inject(x, dx);
  return result;
}

}  // namespace epichead::fusion
