#include "epichead/fusion/pose_update.h"

#include <limits>

#include "epichead/geometry/se3.h"
#include "kalman_update.h"

namespace epichead::fusion {

PoseUpdateResult update_pose(NavState& x, ErrorCovariance& P, const Eigen::Isometry3d& measured_cam_T_obj,
                             const Matrix6d& cov, double gate_chi2, const Matrix6d& gate_widening) {
  // measured = exp(n) exp(xi) estimate exp(e) (e the vision error), so
  // log(measured * expected^-1) ~ xi + Ad e + n = H dx + n.
  const Vector6d r = geometry::se3_log(measured_cam_T_obj * fusion::measured_cam_T_obj(x).inverse());
  const PoseJacobian H = measurement_jacobian(x);
  PoseUpdateResult result;
  if (!gate_widening.isZero(0)) {
    const Eigen::LLT<Matrix6d> wide(H * P * H.transpose() + cov + gate_widening);
    if (wide.info() != Eigen::Success) return {false, std::numeric_limits<double>::infinity()};
    if (!(r.dot(wide.solve(r)) <= gate_chi2)) {
      const Eigen::LLT<Matrix6d> llt(H * P * H.transpose() + cov);
      return {false, llt.info() == Eigen::Success ? r.dot(llt.solve(r)) : std::numeric_limits<double>::infinity()};
    }
    gate_chi2 = std::numeric_limits<double>::infinity();
  }
  ErrorVector dx;
  result.mahalanobis2 = detail::update_error_state<6>(P, H, r, cov, gate_chi2, dx, result.applied);
  if (result.applied) inject(x, dx);
  return result;
}

}  // namespace epichead::fusion
