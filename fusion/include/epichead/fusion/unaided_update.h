#pragma once
// The IMU filter without vision (lost, refused as a wrong lock, or a gap): what the IMU alone
// still says, as Kalman updates of the filter's state (docs/fusion.md, "Without vision"). The
// accelerometer's mean over a window is gravity when the camera does not accelerate on average,
// so the filter's tilt (its attitude against the object's down) stays observable; and a camera on
// a robot does not stray far from where vision last saw it, which bounds the position the way
// PX4's EKF2 fuses its last known position while it has no aiding. Both act on one state and its
// covariance, in place; no allocation.
#include <Eigen/Core>

#include "epichead/fusion/nav_state.h"

namespace epichead::fusion {

struct DownUpdateResult {
  bool applied = false;
  double angle_rad = 0;     // the filter's down against the measured one, before the update
  bool inflated = false;    // the angle exceeded contradiction_rad and the filter's tilt sigma:
                            // its tilt covariance was raised to the angle first
};

// The filter's down, obj_R_cam^T * down_obj, observed as `measured_down_cam` (both unit) with
// 1-sigma sigma_rad in each of the two tilt directions; a turn about the down is not observed.
// A filter whose down is more than contradiction_rad off the measured one (and more than its own
// tilt sigma) has gone wrong the way a tilted pose has (learnt_gravity.h): its tilt variance is
// raised to the angle squared, so that the update takes the measurement rather than trusting the
// state that contradicts it. Not gated otherwise: the caller checks the measurement (|f| near g).
DownUpdateResult update_down(NavState& x, ErrorCovariance& P, const Eigen::Vector3d& down_obj,
                             const Eigen::Vector3d& measured_down_cam, double sigma_rad, double contradiction_rad);

// The camera's position observed at obj_p_cam with 1-sigma sigma_m per axis, only while the
// filter's own position sigma is larger (on any axis): a bound on the drift of an unaided filter,
// not a measurement that would make it confident. True when applied.
bool hold_position(NavState& x, ErrorCovariance& P, const Eigen::Vector3d& obj_p_cam, double sigma_m);

// The pose block (orientation, position) of P raised to at least `floor` (6x6, the filters' pose
// error order, symmetric positive semi-definite): the positive part of floor - P_pose is added, so
// P stays positive semi-definite and its cross-covariances are kept. For a filter going unaided:
// successive vision poses share most of their error (the same edges, seen from nearly the same
// place), so their updates did not average it out, and the filter's pose is known no better than
// one vision pose said (docs/fusion.md, "Without vision"). True when P was raised.
bool floor_pose_covariance(ErrorCovariance& P, const Eigen::Matrix<double, 6, 6>& floor);

}  // namespace epichead::fusion
