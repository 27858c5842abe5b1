#include "epichead/fusion/lie.h"

#include <cmath>

namespace epichead::fusion {
namespace {

// Below this angle the series forms are used: the closed forms lose all digits to cancellation.
constexpr double small_angle = 1e-6;

// V(phi) and its inverse, from the left Jacobian of SO(3) (Barfoot, State Estimation, 7.1.5).
Eigen::Matrix3d left_jacobian(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (a < small_angle) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double b = (1 - std::cos(a)) / (a * a), c = (a - std::sin(a)) / (a * a * a);
  return Eigen::Matrix3d::Identity() + b * W + c * W * W;
}

Eigen::Matrix3d left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (a < small_angle) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
  const double k = (1 - a * std::sin(a) / (2 * (1 - std::cos(a)))) / (a * a);
  return Eigen::Matrix3d::Identity() - 0.5 * W + k * W * W;
}

}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (a < small_angle) return Eigen::Matrix3d::Identity() + W + 0.5 * W * W;
  return Eigen::Matrix3d::Identity() + (std::sin(a) / a) * W + ((1 - std::cos(a)) / (a * a)) * W * W;
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  // Eigen's angle-axis conversion goes through a quaternion and is accurate near 0 and pi.
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Isometry3d se3_exp(const Vector6d& xi) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3_exp(xi.tail<3>());
  T.translation() = left_jacobian(xi.tail<3>()) * xi.head<3>();
  return T;
}

Vector6d se3_log(const Eigen::Isometry3d& T) {
  Vector6d xi;
  xi.tail<3>() = so3_log(T.linear());
  xi.head<3>() = left_jacobian_inverse(xi.tail<3>()) * T.translation();
  return xi;
}

}  // namespace epichead::fusion
