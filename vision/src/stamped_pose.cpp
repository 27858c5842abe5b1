#include "epichead/vision/stamped_pose.h"

namespace epichead::vision {

Eigen::Isometry3d make_pose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

}  // namespace epichead::vision
