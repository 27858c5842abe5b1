#include "epichead/head/target_observation.h"

#include <limits>

namespace epichead::head {

TargetObservation target_from_pose(double t_s, const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& point_obj) {
  return {t_s, cam_T_obj * point_obj};
}

Eigen::Vector2d offset_from_centre_px(const vision::Camera& camera, const Eigen::Vector3d& p_cam) {
  if (!(p_cam.z() > 0)) return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  const auto& k = camera.intrinsics();
  return camera.project(p_cam) - Eigen::Vector2d(k.cx_px, k.cy_px);
}

}  // namespace epichead::head
