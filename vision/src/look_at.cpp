#include "epichead/vision/look_at.h"

#include <cmath>

namespace epichead::vision {

Eigen::Isometry3d look_at(const Eigen::Vector3d& camera_world, const Eigen::Vector3d& target_world,
                          const Eigen::Vector3d& up_world) {
  Eigen::Vector3d z = target_world - camera_world;
  if (z.norm() < 1e-12) z = Eigen::Vector3d::UnitX();
  z.normalize();
  // Image y points down: away from `up` within the image plane.
  Eigen::Vector3d x = z.cross(up_world);
  if (x.norm() < 1e-9) x = z.cross(std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY());
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d world_T_cam = Eigen::Isometry3d::Identity();
  world_T_cam.linear().col(0) = x;
  world_T_cam.linear().col(1) = y;
  world_T_cam.linear().col(2) = z;
  world_T_cam.translation() = camera_world;
  return world_T_cam;
}

}  // namespace epichead::vision
