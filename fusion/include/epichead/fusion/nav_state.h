#pragma once
// The filter's nominal state, its 17-dimensional error state and the maps between them.
// Conventions (docs/fusion.md): the object frame is inertial (the object is static); orientation
// error is local, obj_R_cam_true = obj_R_cam * geometry::so3_exp(dtheta); position, velocity and biases have
// additive errors; gravity is a direction of fixed magnitude with a 2-dof local error.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace epichead::fusion {

constexpr double standard_gravity_mps2 = 9.80665;

// Offsets of the blocks in the error state.
namespace err {
constexpr int theta = 0;   // orientation of the camera, local (camera frame), rad
constexpr int p = 3;       // camera position in the object frame, m
constexpr int v = 6;       // camera velocity in the object frame, m/s
constexpr int bg = 9;      // gyro bias, IMU frame, rad/s
constexpr int ba = 12;     // accelerometer bias, IMU frame, m/s^2
constexpr int grav = 15;   // gravity direction, 2 dof in the gravity frame, rad
constexpr int dim = 17;
}  // namespace err

using ErrorVector = Eigen::Matrix<double, err::dim, 1>;
using ErrorCovariance = Eigen::Matrix<double, err::dim, err::dim>;
using PoseJacobian = Eigen::Matrix<double, 6, err::dim>;

struct NavState {
  Eigen::Matrix3d obj_R_cam = Eigen::Matrix3d::Identity();
  Eigen::Vector3d obj_p_cam = Eigen::Vector3d::Zero();
  Eigen::Vector3d obj_v_cam = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2 = Eigen::Vector3d::Zero();
  // Gravity frame: gravity is (0, 0, -g) there. Its turn about gravity is meaningless and never
  // estimated; keeping a rotation (not a vector) gives a continuous 2-dof error basis.
  Eigen::Matrix3d obj_R_grav = Eigen::Matrix3d::Identity();

  Eigen::Vector3d gravity_obj_mps2() const;
  Eigen::Isometry3d cam_T_obj() const;
};

// A state with the given pose (other members zero, gravity along -z of the object frame).
NavState nav_state_from(const Eigen::Isometry3d& cam_T_obj);

// Gravity frame whose gravity points along `gravity_obj` (any length > 0).
Eigen::Matrix3d gravity_frame_from(const Eigen::Vector3d& gravity_obj);

// Adds an error to the state: x <- x [+] dx.
void inject(NavState& x, const ErrorVector& dx);

// The error dx with truth = estimate [+] dx (for NEES and tests).
ErrorVector error_between(const NavState& truth, const NavState& estimate);

// d(xi)/d(dx): how the error state moves the left perturbation xi = (rho, phi) of cam_T_obj.
PoseJacobian pose_jacobian(const NavState& x);

// d(gravity_obj)/d(gravity error): the 3x2 block used in propagation.
Eigen::Matrix<double, 3, 2> gravity_jacobian(const NavState& x);

}  // namespace epichead::fusion
