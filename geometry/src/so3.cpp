#include "epichead/geometry/so3.h"

#include <cmath>

#include <Eigen/Geometry>

namespace epichead::geometry {
namespace {

// exp and Jl: at or below this angle the first-order forms I + W and I + W/2. Above it the closed
// forms, as the pose solver's apply_left always had them (kept for bit-identical poses). For exp
// that is accurate: the cancellation in 1 - cos(a) only touches the O(a^2) W^2 term. For Jl it is
// not quite: between 1e-12 and ~1e-5 rad its W coefficient (1 - cos a) / a^2 loses digits (all of
// them near 1e-9, where cos(a) rounds to 1), an absolute error up to a / 2 (5e-10 at 1e-9).
// Harmless for the solver's steps, which are accepted on their cost; a series below ~1e-4 would
// fix it and move the poses' last bits.
constexpr double first_order_angle = 1e-12;
// Jl^-1: below this angle the series: its closed-form coefficient divides by 1 - cos(a) and
// loses all digits to cancellation.
constexpr double series_angle = 1e-6;

}  // namespace

Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  if (angle > first_order_angle) {
    const double a = std::sin(angle) / angle, b = (1 - std::cos(angle)) / (angle * angle);
    R += a * W + b * W * W;
  } else {
    R += W;
  }
  return R;
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  // Eigen's angle-axis conversion goes through a quaternion and is accurate near 0 and pi.
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi) {
  const double angle = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
  if (angle > first_order_angle) {
    const double b = (1 - std::cos(angle)) / (angle * angle),
                 c = (angle - std::sin(angle)) / (angle * angle * angle);
    J += b * W + c * W * W;
  } else {
    J += 0.5 * W;
  }
  return J;
}

Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  const Eigen::Matrix3d W = skew(phi);
  if (a < series_angle) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
  const double k = (1 - a * std::sin(a) / (2 * (1 - std::cos(a)))) / (a * a);
  return Eigen::Matrix3d::Identity() - 0.5 * W + k * W * W;
}

Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi) { return so3_left_jacobian(-phi); }

Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi) { return so3_left_jacobian_inverse(-phi); }

Eigen::Matrix3d rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  return Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
}

}  // namespace epichead::geometry
