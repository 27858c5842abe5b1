#include "occluder_motion.h"

namespace epichead::sim {

void occluder_poses_at(const Scene& scene, const Scenario& scenario, double t_s, std::vector<Eigen::Isometry3d>& out) {
  out.clear();
  for (std::size_t j = 0; j < scene.occluders.size(); ++j) {
    const bool has_path = j < scene.occluder_paths.size();
    Eigen::Isometry3d pose = has_path ? occluder_pose(scene.occluder_paths[j], t_s) : Eigen::Isometry3d::Identity();
    const OccluderKey* prev = nullptr;
    const OccluderKey* next = nullptr;
    for (const OccluderKey& k : scenario.occluder_keys) {
      if (k.occluder != static_cast<int>(j)) continue;
      if (k.t_s <= t_s) prev = &k;
      else if (!next) next = &k;
    }
    if (prev || next) {
      if (has_path) pose.linear() = scene.occluder_paths[j].world_T_start.linear();
      if (!prev) pose.translation() = next->position_world;
      else if (!next) pose.translation() = prev->position_world;
      else {
        const double u = (t_s - prev->t_s) / (next->t_s - prev->t_s);
        pose.translation() = prev->position_world + u * (next->position_world - prev->position_world);
      }
    }
    out.push_back(pose);
  }
}

}  // namespace epichead::sim
