#pragma once
// Between the vision covariance (left perturbation xi = (rho, phi) of cam_T_obj) and the filters'
// (orientation error local to the camera, position error in the object frame).
#include <Eigen/Core>

#include "epichead/fusion/lie.h"

namespace epichead::fusion::detail {

// (dtheta, dp) from xi: the inverse of rho = -R' dp, phi = -dtheta.
inline Matrix6d xi_to_theta_p(const Eigen::Matrix3d& obj_R_cam) {
  Matrix6d J = Matrix6d::Zero();
  J.block<3, 3>(0, 3) = -Eigen::Matrix3d::Identity();
  J.block<3, 3>(3, 0) = -obj_R_cam;
  return J;
}

}  // namespace epichead::fusion::detail
