#include "epichead/fusion/nav_state.h"

#include <cmath>

#include "epichead/geometry/so3.h"

namespace epichead::fusion {
namespace {

const Eigen::Vector3d gravity_in_grav_frame{0, 0, -standard_gravity_mps2};

// The two tangent directions of the gravity error (x and y of the gravity frame).
Eigen::Matrix<double, 3, 2> tangent_basis() {
  Eigen::Matrix<double, 3, 2> E = Eigen::Matrix<double, 3, 2>::Zero();
  E(0, 0) = 1;
  E(1, 1) = 1;
  return E;
}

}  // namespace

Eigen::Vector3d NavState::gravity_obj_mps2() const { return obj_R_grav * gravity_in_grav_frame; }

Eigen::Isometry3d NavState::cam_T_obj() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = obj_R_cam.transpose();
  T.translation() = -(obj_R_cam.transpose() * obj_p_cam);
  return T;
}

NavState nav_state_from(const Eigen::Isometry3d& cam_T_obj) {
  NavState x;
  x.obj_R_cam = cam_T_obj.linear().transpose();
  x.obj_p_cam = -(x.obj_R_cam * cam_T_obj.translation());
  return x;
}

Eigen::Matrix3d gravity_frame_from(const Eigen::Vector3d& gravity_obj) {
  return geometry::rotation_between(Eigen::Vector3d(0, 0, -1), gravity_obj);
}

void inject(NavState& x, const ErrorVector& dx) {
  x.obj_R_cam = x.obj_R_cam * geometry::so3_exp(dx.segment<3>(err::theta));
  x.obj_p_cam += dx.segment<3>(err::p);
  x.obj_v_cam += dx.segment<3>(err::v);
  x.gyro_bias_radps += dx.segment<3>(err::bg);
  x.accel_bias_mps2 += dx.segment<3>(err::ba);
  x.obj_R_grav = x.obj_R_grav * geometry::so3_exp(Eigen::Vector3d(dx[err::grav], dx[err::grav + 1], 0));
  // Re-orthonormalise so that round-off does not accumulate over thousands of updates.
  x.obj_R_cam = Eigen::Quaterniond(x.obj_R_cam).normalized().toRotationMatrix();
  x.obj_R_grav = Eigen::Quaterniond(x.obj_R_grav).normalized().toRotationMatrix();
}

ErrorVector error_between(const NavState& truth, const NavState& estimate) {
  ErrorVector dx;
  dx.segment<3>(err::theta) = geometry::so3_log(estimate.obj_R_cam.transpose() * truth.obj_R_cam);
  dx.segment<3>(err::p) = truth.obj_p_cam - estimate.obj_p_cam;
  dx.segment<3>(err::v) = truth.obj_v_cam - estimate.obj_v_cam;
  dx.segment<3>(err::bg) = truth.gyro_bias_radps - estimate.gyro_bias_radps;
  dx.segment<3>(err::ba) = truth.accel_bias_mps2 - estimate.accel_bias_mps2;
  // The rotation (about an axis normal to gravity) that turns the estimated gravity into the true
  // one, in the estimate's gravity frame.
  const Eigen::Vector3d g_true = estimate.obj_R_grav.transpose() * truth.gravity_obj_mps2();
  const Eigen::Vector3d axis = gravity_in_grav_frame.cross(g_true);
  const double angle = std::atan2(axis.norm(), gravity_in_grav_frame.dot(g_true));
  const Eigen::Vector3d phi = axis.norm() > 0 ? Eigen::Vector3d(angle * axis.normalized()) : Eigen::Vector3d::Zero();
  dx[err::grav] = phi.x();
  dx[err::grav + 1] = phi.y();
  return dx;
}

PoseJacobian pose_jacobian(const NavState& x) {
  // cam_T_obj = (obj_R_cam^T, -obj_R_cam^T p). With obj_R_cam <- R exp(dtheta), p <- p + dp, the left
  // perturbation is rho = -R^T dp, phi = -dtheta to first order (docs/fusion.md).
  PoseJacobian H = PoseJacobian::Zero();
  H.block<3, 3>(0, err::p) = -x.obj_R_cam.transpose();
  H.block<3, 3>(3, err::theta) = -Eigen::Matrix3d::Identity();
  return H;
}

Eigen::Matrix<double, 3, 2> gravity_jacobian(const NavState& x) {
  // g(dg) = R_grav exp([dg, 0]) g0  =>  dg/d(dg) = -R_grav [g0]x E.
  return -x.obj_R_grav * geometry::skew(gravity_in_grav_frame) * tangent_basis();
}

}  // namespace epichead::fusion
