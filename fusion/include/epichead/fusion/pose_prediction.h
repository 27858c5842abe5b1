#pragma once
// A predicted camera pose for window placement.
#include <Eigen/Geometry>

#include "epichead/geometry/se3.h"

namespace epichead::fusion {

using geometry::Matrix6d;
using geometry::Vector6d;

struct PosePrediction {
  double t_s = 0;
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();  // of the left perturbation (translation, rotation)
  double extrapolated_s = 0;  // time bridged without measurements (beyond the newest IMU sample or update)
};

}  // namespace epichead::fusion
