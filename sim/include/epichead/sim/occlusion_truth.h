#pragma once
// Whether a scene's moving occluders (cover boards, poles) hide the whole tracked object from a
// camera at a time: the truth behind "frames in which nothing of the object can be measured",
// which scoring leaves out. The object is hidden when the line of sight to every vertex of its
// rendered mesh meets an occluder's triangle first -- a test on what is drawn, so a board that
// already fills the view while it is still sliding in counts, and one whose edge still leaves a
// sliver of the object in view does not.
#include <vector>

#include <Eigen/Geometry>

#include "epichead/sim/scenario.h"
#include "epichead/sim/scene.h"

namespace epichead::sim {

class OcclusionTruth {
 public:
  // Copies what it needs (the object mesh's vertices in the world, the occluders, their paths
  // and the scenario's occluder keys): the scene may be moved or destroyed afterwards.
  OcclusionTruth(const Scene& scene, const Scenario& scenario);

  // True when the occluders, posed at t_s, hide every vertex of the object from the camera at
  // world_T_cam. False without occluders.
  bool hides_object(double t_s, const Eigen::Isometry3d& world_T_cam);

 private:
  Scene occluders_;   // only `occluders` and `occluder_paths` are filled
  Scenario keys_;     // only `occluder_keys` is filled
  std::vector<Eigen::Vector3d> object_world_;     // the object mesh's distinct vertices, world frame
  std::vector<Eigen::Isometry3d> poses_;          // scratch: occluder_T_world at the asked time
};

}  // namespace epichead::sim
