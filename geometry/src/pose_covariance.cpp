#include "epichead/geometry/pose_covariance.h"

namespace epichead::geometry {

Matrix6d diagonal_pose_covariance(double sigma_t_m, double sigma_r_rad) {
  Matrix6d c = Matrix6d::Zero();
  const double t = sigma_t_m, r = sigma_r_rad;
  c.diagonal() << t * t, t * t, t * t, r * r, r * r, r * r;
  return c;
}

Matrix6d filter_pose_error_jacobian(const Eigen::Matrix3d& obj_R_cam) {
  // The inverse of rho = -obj_R_cam' dp, phi = -dtheta.
  Matrix6d J = Matrix6d::Zero();
  J.block<3, 3>(0, 3) = -Eigen::Matrix3d::Identity();
  J.block<3, 3>(3, 0) = -obj_R_cam;
  return J;
}

}  // namespace epichead::geometry
