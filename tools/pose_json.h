#pragma once
// A pose in report and result JSON: {"t_m": [x, y, z], "q_wxyz": [w, x, y, z]} (camera from
// object, as in poses.csv), the one shape `detect` and `track` write.
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace epichead::tools {

inline nlohmann::json pose_json(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  return {{"t_m", {T.translation().x(), T.translation().y(), T.translation().z()}}, {"q_wxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

}  // namespace epichead::tools
