#pragma once
// Pan/tilt kinematics between the robot body and the camera, in the simulator's convention
// (sim/head_mount.h), so the simulator can switch to this code:
//   body -> translate pan_origin_body -> pan: rotation about body z (positive turns left)
//        -> translate tilt_origin_pan -> tilt: rotation about the pan frame's y (positive looks down)
//        -> translate cam_offset_tilt -> camera axes tilt_R_cam = nominal * Rz * Ry * Rx (misalignment).
// Nominal camera axes in the tilt frame: camera x = -tilt y, y = -tilt z, z (optical axis) = tilt x.
// Body frame: x forward, y left, z up. Camera frame: x right, y down, z forward.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace epichead::head {

// The mount's calibration (the sim's defaults).
struct HeadMount {
  Eigen::Vector3d pan_origin_body{0.10, 0.0, 0.35};  // pan axis foot on the body (m)
  Eigen::Vector3d tilt_origin_pan{0.0, 0.0, 0.06};   // tilt axis in the pan frame (m)
  Eigen::Vector3d cam_offset_tilt{0.03, 0.0, 0.0};   // camera centre in the tilt frame (m)
  Eigen::Vector3d cam_misalign_rad = Eigen::Vector3d::Zero();  // about camera x, y, z (small)
};

struct JointAngles {
  double pan_rad = 0, tilt_rad = 0;
};

// Nominal camera axes in the tilt frame (columns: camera x, y, z in tilt coordinates).
Eigen::Matrix3d tilt_R_cam_nominal();
// The camera axes in the tilt frame including the mount misalignment.
Eigen::Matrix3d tilt_R_cam(const HeadMount& mount);
// Camera pose in the body frame for the given joint angles.
Eigen::Isometry3d body_T_cam(const HeadMount& mount, const JointAngles& q);
// Camera pose in the world from the body pose and the joint angles.
Eigen::Isometry3d world_T_cam(const Eigen::Isometry3d& world_T_body, const HeadMount& mount, const JointAngles& q);

// Camera angular velocity relative to the body, in camera axes, per unit joint rate:
// column 0 the pan axis, column 1 the tilt axis (unit vectors). omega_cam = J * (pan_rate, tilt_rate).
Eigen::Matrix<double, 3, 2> joint_axes_cam(const HeadMount& mount, const JointAngles& q);

// Joint angles that point the optical axis (nominal mount) at a point given in the body frame;
// the same solution as sim::aim_at. The camera offset along the optical axis does not matter.
JointAngles aim_joints(const HeadMount& mount, const Eigen::Vector3d& target_body);

}  // namespace epichead::head
