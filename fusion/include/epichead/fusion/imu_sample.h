#pragma once
// One IMU reading as the device reports it.
#include <Eigen/Core>

namespace epichead::fusion {

struct ImuSample {
  double t_s = 0;  // device clock; the predictor maps it to the camera clock (t_camera = t_s - offset)
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();  // IMU frame
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();  // specific force (a - g), IMU frame
};

}  // namespace epichead::fusion
