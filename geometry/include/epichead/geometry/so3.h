#pragma once
// SO(3): the hat map, exp and log, and the left and right Jacobians (Barfoot, State Estimation
// for Robotics, 7.1). Rotation vectors phi are in radians; the angle is |phi|.
#include <Eigen/Core>

namespace epichead::geometry {

// [v]x: skew(v) * w = v.cross(w). Inline: the pose solver builds one per feature per iteration.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Rotation of angle |phi| about phi (Rodrigues); any phi.
Eigen::Matrix3d so3_exp(const Eigen::Vector3d& phi);

// Inverse of so3_exp; R orthonormal. The angle returned is in [0, pi].
Eigen::Vector3d so3_log(const Eigen::Matrix3d& R);

// Left Jacobian Jl(phi): so3_exp(phi + d) = so3_exp(Jl d) so3_exp(phi) to first order; any phi.
Eigen::Matrix3d so3_left_jacobian(const Eigen::Vector3d& phi);

// Jl(phi)^-1; |phi| < 2 pi (Jl is singular at 2 pi).
Eigen::Matrix3d so3_left_jacobian_inverse(const Eigen::Vector3d& phi);

// Right Jacobian Jr(phi) = Jl(-phi): so3_exp(phi + d) = so3_exp(phi) so3_exp(Jr d); any phi.
Eigen::Matrix3d so3_right_jacobian(const Eigen::Vector3d& phi);

// Jr(phi)^-1 = Jl(-phi)^-1; |phi| < 2 pi.
Eigen::Matrix3d so3_right_jacobian_inverse(const Eigen::Vector3d& phi);

// The smallest rotation that turns the direction of `from` into that of `to` (Eigen's
// Quaterniond::FromTwoVectors; neither may be zero). One definition for every caller: the SVD
// Eigen keeps for opposite directions costs each file that instantiates it about 16 s to compile
// under the sanitizers.
Eigen::Matrix3d rotation_between(const Eigen::Vector3d& from, const Eigen::Vector3d& to);

}  // namespace epichead::geometry
