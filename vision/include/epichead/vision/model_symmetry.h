#pragma once
// The turns that leave a model's points where they were (a box's half turns about its axes):
// poses that differ by one of them draw the same wire-frame, so neither the tracker nor
// detection can tell them apart without texture. Scoring removes them as it removes the free
// turn of a body of revolution.
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "epichead/vision/cao_model.h"

namespace epichead::vision {

// The proper rotations about the model's centroid, among the 24 that permute its principal
// axes, that map every vertex onto a vertex (within a thousandth of the model's size); the
// identity is left out. Empty for a model with fewer than three vertices or no such turn.
std::vector<Eigen::Isometry3d> model_symmetries(const CadModel& model);

// Of cam_T_obj and its equivalents cam_T_obj * S (S among `symmetries`), the one whose turn is
// nearest like's (the smallest rotation between them): no outline can choose among them, a
// prior pose can (the prediction after a loss, the tracked pose on a recheck).
Eigen::Isometry3d symmetric_nearest(const Eigen::Isometry3d& cam_T_obj, const std::vector<Eigen::Isometry3d>& symmetries,
                                    const Eigen::Isometry3d& like);
// The one that puts the object's up (up_obj, model frame) nearest the world's up in the camera
// frame (up_cam): gravity's choice when there is no prior pose.
Eigen::Isometry3d symmetric_upright(const Eigen::Isometry3d& cam_T_obj, const std::vector<Eigen::Isometry3d>& symmetries,
                                    const Eigen::Vector3d& up_obj, const Eigen::Vector3d& up_cam);

// The smallest turn (rad) between cam_R_a and cam_R_b or any of its equivalents cam_R_b * S (S
// among `symmetries`): how far two poses are turned apart as far as any outline can tell. With
// free_axis_obj (a body of revolution, revolution_axis.h; unit, model frame) only the axis's own
// direction counts, since the turn about it is no pose's to tell.
double symmetric_turn_rad(const Eigen::Matrix3d& cam_R_a, const Eigen::Matrix3d& cam_R_b,
                          const std::vector<Eigen::Isometry3d>& symmetries,
                          const std::optional<Eigen::Vector3d>& free_axis_obj = std::nullopt);

}  // namespace epichead::vision
