#pragma once
// Occluder poses at a time: the scenario's keys when an occluder has any, else the scene's
// default path. Shared by the sequence writer and the closed-loop camera.
#include <vector>

#include <Eigen/Geometry>

#include "epichead/sim/scenario.h"
#include "epichead/sim/scene.h"

namespace epichead::sim {

// Fills `out` (one pose per scene occluder); `out` keeps its capacity, so no allocation once sized.
void occluder_poses_at(const Scene& scene, const Scenario& scenario, double t_s, std::vector<Eigen::Isometry3d>& out);

}  // namespace epichead::sim
