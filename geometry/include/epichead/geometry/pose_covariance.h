#pragma once
// The pose-covariance convention every module shares. A pose covariance is the 6x6 covariance of
// the left perturbation xi = (rho, phi) of cam_T_obj, cam_T_obj_true = se3_exp(xi) * cam_T_obj:
// translation (m) first, then rotation (rad), both in the camera frame. The filters keep their
// own pose error (dtheta, dp), converted here. Tuning values (how much to trust a tracked pose,
// how uncertain init.csv is) belong to their modules.
#include <Eigen/Core>

#include "epichead/geometry/se3.h"

namespace epichead::geometry {

// Offsets of the blocks of xi and of a pose covariance.
namespace pose_cov {
constexpr int translation = 0;  // rho, m
constexpr int rotation = 3;     // phi, rad
}  // namespace pose_cov

// Independent axes: sigma_t_m on each translation axis, sigma_r_rad on each rotation axis.
Matrix6d diagonal_pose_covariance(double sigma_t_m, double sigma_r_rad);

// d(dtheta, dp) / d(xi) for the filters' pose error: orientation error local to the camera,
// obj_R_cam_true = obj_R_cam * so3_exp(dtheta), and the camera position's additive error dp in
// the object frame. To first order phi = -dtheta and rho = -obj_R_cam' dp; obj_R_cam a rotation.
Matrix6d filter_pose_error_jacobian(const Eigen::Matrix3d& obj_R_cam);

}  // namespace epichead::geometry
