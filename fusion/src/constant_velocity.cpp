#include "epichead/fusion/constant_velocity.h"

#include <cmath>

#include "epichead/fusion/free_direction.h"
#include "epichead/geometry/pose_covariance.h"
#include "epichead/geometry/se3.h"
#include "epichead/geometry/so3.h"
#include "kalman_update.h"

namespace epichead::fusion {
namespace {

constexpr int th = 0, p = 3, v = 6, w = 9;

Eigen::Matrix<double, 6, ConstantVelocityFilter::dim> cv_pose_jacobian(const Eigen::Matrix3d& obj_R_cam) {
  Eigen::Matrix<double, 6, ConstantVelocityFilter::dim> H = Eigen::Matrix<double, 6, ConstantVelocityFilter::dim>::Zero();
  H.block<3, 3>(0, p) = -obj_R_cam.transpose();
  H.block<3, 3>(3, th) = -Eigen::Matrix3d::Identity();
  return H;
}

Eigen::Isometry3d to_cam_T_obj(const Eigen::Matrix3d& obj_R_cam, const Eigen::Vector3d& obj_p_cam) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = obj_R_cam.transpose();
  T.translation() = -(obj_R_cam.transpose() * obj_p_cam);
  return T;
}

}  // namespace

bool ConstantVelocityFilter::initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  t_s_ = t_s;
  obj_R_cam_ = cam_T_obj.linear().transpose();
  obj_p_cam_ = -(obj_R_cam_ * cam_T_obj.translation());
  obj_v_cam_.setZero();
  omega_cam_radps_.setZero();
  P_.setZero();
  const Matrix6d J = geometry::filter_pose_error_jacobian(obj_R_cam_);
  P_.topLeftCorner<6, 6>() = J * start_covariance(cov) * J.transpose();
  P_.block<3, 3>(v, v).diagonal().setConstant(noise_.initial_speed_mps * noise_.initial_speed_mps);
  P_.block<3, 3>(w, w).diagonal().setConstant(noise_.initial_rate_radps * noise_.initial_rate_radps);
  return true;
}

void ConstantVelocityFilter::propagate(double dt, Eigen::Matrix3d& R, Eigen::Vector3d& pos, Covariance& P) const {
  const Eigen::Matrix3d dR = geometry::so3_exp(omega_cam_radps_ * dt);
  R = R * dR;
  pos += obj_v_cam_ * dt;
  Covariance F = Covariance::Identity();
  F.block<3, 3>(th, th) = dR.transpose();
  F.block<3, 3>(th, w) = Eigen::Matrix3d::Identity() * dt;
  F.block<3, 3>(p, v) = Eigen::Matrix3d::Identity() * dt;
  P = F * P * F.transpose();
  // White acceleration integrated twice (the usual constant-velocity noise), also for dt < 0.
  const double a = std::abs(dt);
  const double qa = noise_.accel_mps2_rths * noise_.accel_mps2_rths;
  const double qw = noise_.angular_accel_radps2_rths * noise_.angular_accel_radps2_rths;
  const double q11 = a * a * a / 3, q12 = a * a / 2, q22 = a;
  for (int i = 0; i < 3; ++i) {
    P(p + i, p + i) += qa * q11;
    P(p + i, v + i) += qa * q12;
    P(v + i, p + i) += qa * q12;
    P(v + i, v + i) += qa * q22;
    P(th + i, th + i) += qw * q11;
    P(th + i, w + i) += qw * q12;
    P(w + i, th + i) += qw * q12;
    P(w + i, w + i) += qw * q22;
  }
}

std::optional<PoseUpdateResult> ConstantVelocityFilter::update(double t_s, const Eigen::Isometry3d& cam_T_obj,
                                                               const Matrix6d& cov, double gate_chi2) {
  Eigen::Matrix3d R = obj_R_cam_;
  Eigen::Vector3d pos = obj_p_cam_;
  Covariance P = P_;
  propagate(t_s - t_s_, R, pos, P);
  const Vector6d r = geometry::se3_log(cam_T_obj * to_cam_T_obj(R, pos).inverse());
  Eigen::Matrix<double, dim, 1> dx;
  PoseUpdateResult result;
  result.mahalanobis2 = detail::kalman_update<dim>(P, cv_pose_jacobian(R), r, cov, gate_chi2, dx, result.applied);
  if (!result.applied) return result;  // a gated pose leaves the filter where it was
  t_s_ = t_s;
  obj_R_cam_ = Eigen::Quaterniond(R * geometry::so3_exp(dx.segment<3>(th))).normalized().toRotationMatrix();
  obj_p_cam_ = pos + dx.segment<3>(p);
  obj_v_cam_ += dx.segment<3>(v);
  omega_cam_radps_ += dx.segment<3>(w);
  P_ = P;
  return result;
}

std::optional<PosePrediction> ConstantVelocityFilter::predict(double t_s) const {
  Eigen::Matrix3d R = obj_R_cam_;
  Eigen::Vector3d pos = obj_p_cam_;
  Covariance P = P_;
  propagate(t_s - t_s_, R, pos, P);
  const auto H = cv_pose_jacobian(R);
  PosePrediction out;
  out.t_s = t_s;
  out.cam_T_obj = to_cam_T_obj(R, pos);
  out.covariance = H * P * H.transpose();
  out.extrapolated_s = std::abs(t_s - t_s_);
  return out;
}

}  // namespace epichead::fusion
