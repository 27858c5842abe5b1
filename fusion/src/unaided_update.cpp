#include "epichead/fusion/unaided_update.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "epichead/geometry/so3.h"
#include "kalman_update.h"

namespace epichead::fusion {

DownUpdateResult update_down(NavState& x, ErrorCovariance& P, const Eigen::Vector3d& down_obj,
                             const Eigen::Vector3d& measured_down_cam, double sigma_rad, double contradiction_rad) {
  DownUpdateResult result;
  if (!down_obj.allFinite() || !measured_down_cam.allFinite() || down_obj.norm() < 1e-9 || measured_down_cam.norm() < 1e-9 ||
      !(sigma_rad > 0))
    return result;
  const Eigen::Vector3d u = (x.obj_R_cam.transpose() * down_obj).normalized();  // the filter's down, camera frame
  const Eigen::Vector3d m = measured_down_cam.normalized();
  const Eigen::Vector3d axis = u.cross(m);
  result.angle_rad = std::atan2(axis.norm(), u.dot(m));
  // With obj_R_cam_true = R exp(dtheta), the true down is exp(-dtheta) u = u + [u]x dtheta: only
  // the two directions of dtheta across u move it. The residual is the measured down's offset
  // along them, as an angle (so that a large one is not shrunk by the sine).
  const Eigen::Vector3d phi = axis.norm() > 0 ? Eigen::Vector3d(result.angle_rad * axis.normalized()) : Eigen::Vector3d::Zero();
  const Eigen::Vector3d offset = phi.cross(u);
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = u.unitOrthogonal();
  B.col(1) = u.cross(B.col(0));
  const Eigen::Vector2d r = B.transpose() * offset;
  Eigen::Matrix<double, 2, err::dim> H = Eigen::Matrix<double, 2, err::dim>::Zero();
  H.block<2, 3>(0, err::theta) = B.transpose() * geometry::skew(u);
  const Eigen::Matrix2d tilt_cov = H * P * H.transpose();
  if (result.angle_rad > contradiction_rad && result.angle_rad * result.angle_rad > tilt_cov.diagonal().maxCoeff()) {
    P.block<3, 3>(err::theta, err::theta) += result.angle_rad * result.angle_rad * (Eigen::Matrix3d::Identity() - u * u.transpose());
    result.inflated = true;
  }
  ErrorVector dx;
  const Eigen::Matrix2d Rm = sigma_rad * sigma_rad * Eigen::Matrix2d::Identity();
  detail::kalman_update<err::dim, 2>(P, H, r, Rm, std::numeric_limits<double>::infinity(), dx, result.applied);
  if (result.applied) inject(x, dx);
  return result;
}

bool hold_position(NavState& x, ErrorCovariance& P, const Eigen::Vector3d& obj_p_cam, double sigma_m) {
  if (!obj_p_cam.allFinite() || !(sigma_m > 0)) return false;
  const double d2 = (obj_p_cam - x.obj_p_cam).squaredNorm(), s2 = sigma_m * sigma_m;
  const double p_var = P.diagonal().segment<3>(err::p).maxCoeff();
  if (d2 <= s2 && p_var <= s2) return false;  // within the bound, and the filter knows it
  // Further off than the bound and than the filter believes: it drifted (a velocity taken wrong
  // over a gap), and it is told so before the update, as update_down does with a contradicting tilt.
  if (d2 > s2 && d2 > p_var) P.diagonal().segment<3>(err::p).array() += d2;
  Eigen::Matrix<double, 3, err::dim> H = Eigen::Matrix<double, 3, err::dim>::Zero();
  H.block<3, 3>(0, err::p).setIdentity();
  const Eigen::Vector3d r = obj_p_cam - x.obj_p_cam;
  const Eigen::Matrix3d Rm = sigma_m * sigma_m * Eigen::Matrix3d::Identity();
  ErrorVector dx;
  bool applied = false;
  detail::kalman_update<err::dim, 3>(P, H, r, Rm, std::numeric_limits<double>::infinity(), dx, applied);
  if (applied) inject(x, dx);
  return applied;
}

bool floor_pose_covariance(ErrorCovariance& P, const Eigen::Matrix<double, 6, 6>& floor) {
  if (!floor.allFinite()) return false;
  const Eigen::Matrix<double, 6, 6> d = 0.5 * (floor + floor.transpose()) - P.topLeftCorner<6, 6>();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(d);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues().maxCoeff() > 0)) return false;
  const Eigen::Matrix<double, 6, 1> raise = eig.eigenvalues().cwiseMax(0.0);
  P.topLeftCorner<6, 6>() += eig.eigenvectors() * raise.asDiagonal() * eig.eigenvectors().transpose();
  return true;
}

}  // namespace epichead::fusion
