#pragma once
// Placing a camera: the pose of a camera at a point looking at a target.
#include <Eigen/Geometry>

namespace epichead::vision {

// world_T_cam for a camera at `camera_world` looking at `target_world`, image up as close to
// `up_world` as possible (camera frame: x right, y down, z forward). Its inverse is cam_T_world.
Eigen::Isometry3d look_at(const Eigen::Vector3d& camera_world, const Eigen::Vector3d& target_world,
                          const Eigen::Vector3d& up_world = Eigen::Vector3d::UnitZ());

}  // namespace epichead::vision
