// The pose-covariance convention: translation then rotation, and the Jacobian to the filters'
// pose error (local orientation error, camera position error in the object frame).
#include <catch2/catch.hpp>

#include "epichead/geometry/pose_covariance.h"
#include "epichead/geometry/so3.h"

using namespace epichead::geometry;

TEST_CASE("diagonal_pose_covariance puts translation first, then rotation") {
  const Matrix6d c = diagonal_pose_covariance(0.01, 0.02);
  CHECK(c(pose_cov::translation, pose_cov::translation) == 0.01 * 0.01);
  CHECK(c(pose_cov::translation + 2, pose_cov::translation + 2) == 0.01 * 0.01);
  CHECK(c(pose_cov::rotation, pose_cov::rotation) == 0.02 * 0.02);
  CHECK(c(pose_cov::rotation + 2, pose_cov::rotation + 2) == 0.02 * 0.02);
  CHECK((c - Matrix6d(c.diagonal().asDiagonal())).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("filter_pose_error_jacobian maps a left perturbation to the filters' (dtheta, dp)") {
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  cam_T_obj.linear() = so3_exp(Eigen::Vector3d(0.3, -0.5, 0.2));
  cam_T_obj.translation() = Eigen::Vector3d(0.1, 0.05, 0.8);
  const Eigen::Matrix3d obj_R_cam = cam_T_obj.linear().transpose();
  const Eigen::Vector3d obj_p_cam = -(obj_R_cam * cam_T_obj.translation());
  constexpr double h = 1e-6;
  Matrix6d numeric;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Isometry3d moved = se3_exp(h * Vector6d::Unit(k)) * cam_T_obj;
    const Eigen::Matrix3d R = moved.linear().transpose();
    numeric.col(k).head<3>() = so3_log(obj_R_cam.transpose() * R) / h;  // obj_R_cam * exp(dtheta)
    numeric.col(k).tail<3>() = (-(R * moved.translation()) - obj_p_cam) / h;
  }
  CHECK((filter_pose_error_jacobian(obj_R_cam) - numeric).cwiseAbs().maxCoeff() < 1e-5);
}
