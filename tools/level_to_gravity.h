#pragma once
// A detected pose turned so that the object's up lies along the up the accelerometer measures.
// Detection's refinement settles where the outline's edges pull it, and on the can that is the
// printed label band's border, 7-9 deg tilted (docs/detection.md); under the 10 deg check a
// filter seeded there holds the tilt for good. With the IMU and the object's learnt down, the tilt
// is known better than any outline gives it (held-out can 107: 0.44 deg). The turn is the
// smallest that does it, about the model's centre, so the object stays where the image shows it;
// the turn about the up (which gravity cannot tell) is kept.
#include <cmath>

#include <Eigen/Geometry>

#include "track_prediction.h"

namespace epichead::tools {

inline Eigen::Isometry3d level_to_gravity(const Eigen::Isometry3d& cam_T_obj, const Upright& up, const Eigen::Vector3d& centre_obj) {
  const Eigen::Vector3d from = (cam_T_obj.linear() * up.up_obj).normalized();
  const Eigen::Vector3d to = up.up_cam.normalized();
  if (!from.allFinite() || !to.allFinite()) return cam_T_obj;
  const Eigen::Matrix3d turn = Eigen::Quaterniond::FromTwoVectors(from, to).toRotationMatrix();
  Eigen::Isometry3d out = cam_T_obj;
  out.linear() = turn * cam_T_obj.linear();
  out.translation() = cam_T_obj * centre_obj - out.linear() * centre_obj;
  return out;
}

}  // namespace epichead::tools
