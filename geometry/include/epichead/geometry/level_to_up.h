#pragma once
// A pose turned so that the object's up lies along a measured up (the accelerometer's, in the
// camera frame): the smallest turn that does it, about a pivot on the object, so the object stays
// where the image shows it; the turn about the up (which gravity cannot tell) is kept. Detection's
// refinement settles where the outline's edges pull it, and on the can that is the printed label
// band's border, 7-9 deg tilted (docs/detection.md); with the IMU and the object's learnt down the
// tilt is known better than any outline gives it (held-out can 107: 0.44 deg).
#include <Eigen/Geometry>

namespace epichead::geometry {

// cam_T_obj levelled: (cam_T_obj.linear() * up_obj) turned onto up_cam, pivot_obj fixed in the
// camera frame. Either up non-finite or zero: cam_T_obj unchanged.
Eigen::Isometry3d level_to_up(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& up_obj,
                              const Eigen::Vector3d& up_cam, const Eigen::Vector3d& pivot_obj);

}  // namespace epichead::geometry
