#include "epichead/geometry/se3.h"

#include "epichead/geometry/so3.h"

namespace epichead::geometry {

Eigen::Isometry3d se3_exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>(), phi = xi.tail<3>();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(phi);
  T.translation() = so3_left_jacobian(phi) * rho;
  return T;
}

Vector6d se3_log(const Eigen::Isometry3d& T) {
  Vector6d xi;
  xi.tail<3>() = so3_log(T.linear());
  xi.head<3>() = so3_left_jacobian_inverse(xi.tail<3>()) * T.translation();
  return xi;
}

Eigen::Isometry3d apply_left(const Vector6d& xi, const Eigen::Isometry3d& pose) {
  Eigen::Isometry3d out = se3_exp(xi) * pose;
  out.linear() = Eigen::Quaterniond(out.linear()).normalized().toRotationMatrix();
  return out;
}

Eigen::Matrix<double, 3, 6> left_point_jacobian(const Eigen::Vector3d& X) {
  Eigen::Matrix<double, 3, 6> J;
  J.leftCols<3>().setIdentity();
  J.rightCols<3>() = -skew(X);
  return J;
}

}  // namespace epichead::geometry
