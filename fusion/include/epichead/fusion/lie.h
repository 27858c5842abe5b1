#pragma once
// The SO(3) and SE(3) maps the filter needs. Eigen has no SE(3) log, and the SE(3) exp must match
// vision::apply_left exactly (fusion may not include vision/), so both are written here.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace epichead::fusion {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// [v]x: skew(v) * w = v.cross(w).
Eigen::Matrix3d skew(const Eigen::Vector3d& v);

// Rotation of angle |phi| about phi (Rodrigues).
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi);

// Inverse of so3_exp for an orthonormal matrix; the angle is in [0, pi].
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);

// exp of xi = (rho, phi): rotation so3_exp(phi), translation V(phi) * rho (as vision::apply_left).
Eigen::Isometry3d se3_exp(const Vector6d& xi);

// Inverse of se3_exp: (rho, phi) with phi = so3_log(R), rho = V(phi)^-1 * t.
Vector6d se3_log(const Eigen::Isometry3d& T);

}  // namespace epichead::fusion
