#include "epichead/geometry/level_to_up.h"

#include "epichead/geometry/so3.h"

namespace epichead::geometry {

Eigen::Isometry3d level_to_up(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& up_obj,
                              const Eigen::Vector3d& up_cam, const Eigen::Vector3d& pivot_obj) {
  const Eigen::Vector3d from = (cam_T_obj.linear() * up_obj).normalized();
  const Eigen::Vector3d to = up_cam.normalized();
  if (!from.allFinite() || !to.allFinite() || from.isZero(0) || to.isZero(0)) return cam_T_obj;
  const Eigen::Matrix3d turn = rotation_between(from, to);
  Eigen::Isometry3d out = cam_T_obj;
  out.linear() = turn * cam_T_obj.linear();
  out.translation() = cam_T_obj * pivot_obj - out.linear() * pivot_obj;
  return out;
}

}  // namespace epichead::geometry
