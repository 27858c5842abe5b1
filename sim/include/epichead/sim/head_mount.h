#pragma once
// The pan/tilt head between the robot body and the camera:
// body -> pan joint (about body z) -> tilt joint (about the pan frame's y; positive looks down)
// -> camera, with a mount calibration (the camera's small offset and misalignment on the tilt
// link). Head angles are a function of time so that a closed-loop controller can drive them later.
#include <functional>

#include <Eigen/Geometry>

#include "epichead/sim/trajectory.h"

namespace epichead::sim {

// Joint angles with their rates and accelerations (the IMU sees head motion too).
struct HeadAngles {
  double pan_rad = 0, tilt_rad = 0;
  double pan_rate_radps = 0, tilt_rate_radps = 0;
  double pan_accel_radps2 = 0, tilt_accel_radps2 = 0;
};

// Head angles at a time. Fixed angles now; a controller supplies its own function later.
using HeadSchedule = std::function<HeadAngles(double t_s)>;
HeadSchedule fixed_head(double pan_rad, double tilt_rad);

struct HeadMount {
  Eigen::Vector3d pan_origin_body{0.10, 0.0, 0.35};  // pan axis foot on the body (m)
  Eigen::Vector3d tilt_origin_pan{0.0, 0.0, 0.06};   // tilt axis in the pan frame (m)
  Eigen::Vector3d cam_offset_tilt{0.03, 0.0, 0.0};   // camera centre in the tilt frame (m)
  // Mount misalignment: small rotation of the camera about its own x, y, z axes (rad),
  // tilt_R_cam = nominal * Rz(z) * Ry(y) * Rx(x).
  Eigen::Vector3d cam_misalign_rad = Eigen::Vector3d::Zero();
};

// The nominal camera axes in the tilt frame: camera z = tilt x (forward), x = -y, y = -z.
Eigen::Matrix3d tilt_R_cam_nominal();
// Camera motion relative to the body for the given joint state.
Kinematics body_T_cam(const HeadMount& mount, const HeadAngles& angles);
// Fixed joint angles that point the camera's optical axis (nominal mount) at target_world
// when the body is at world_T_body.
HeadAngles aim_at(const HeadMount& mount, const Eigen::Isometry3d& world_T_body, const Eigen::Vector3d& target_world);

}  // namespace epichead::sim
