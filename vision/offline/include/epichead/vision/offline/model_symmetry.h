#pragma once
// The turns that leave a model's points where they were (a box's half turns about its axes):
// poses that differ by one of them draw the same wire-frame, so neither the tracker nor
// detection can tell them apart without texture. Scoring removes them as it removes the free
// turn of a body of revolution.
#include <vector>

#include <Eigen/Geometry>

#include "epichead/vision/cao_model.h"

namespace epichead::vision {

// The proper rotations about the model's centroid, among the 24 that permute its principal
// axes, that map every vertex onto a vertex (within a thousandth of the model's size); the
// identity is left out. Empty for a model with fewer than three vertices or no such turn.
std::vector<Eigen::Isometry3d> model_symmetries(const CadModel& model);

}  // namespace epichead::vision
