#pragma once
// SE(3) on Eigen::Isometry3d with twists xi = (rho, phi): translation part first, then rotation
// (the order of every pose covariance, see pose_covariance.h). exp(xi) = [so3_exp(phi), Jl(phi) rho].
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace epichead::geometry {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// exp of xi = (rho, phi): rotation so3_exp(phi), translation so3_left_jacobian(phi) * rho.
Eigen::Isometry3d se3_exp(const Vector6d& xi);

// Inverse of se3_exp; T's linear part orthonormal. phi = so3_log(R) (angle in [0, pi]),
// rho = so3_left_jacobian_inverse(phi) * t.
Vector6d se3_log(const Eigen::Isometry3d& T);

// The left perturbation se3_exp(xi) * pose, re-orthonormalised (through a unit quaternion) so
// that round-off does not accumulate over many updates; pose's linear part a rotation.
Eigen::Isometry3d apply_left(const Vector6d& xi, const Eigen::Isometry3d& pose);

// d(se3_exp(xi) * X) / d(xi) at xi = 0, for the point X = pose * p: [I | -[X]x].
Eigen::Matrix<double, 3, 6> left_point_jacobian(const Eigen::Vector3d& X);

}  // namespace epichead::geometry
