#pragma once
// The object's orientation in the camera frame carried by the gyro alone from the last time the
// filter knew it. The filter forgets its whole state after a long loss, since its position and
// velocity have drifted away by then; a gyro's turn has not (a MEMS gyro's bias, once the filter
// estimated it, leaves a few tenths of a degree a second). What is carried says which way the
// object is turned when it comes back into view, so that detection does not take an outline of
// clutter turned otherwise (docs/fusion.md, "The orientation carried across a loss").
// No allocation.
#include <numbers>
#include <optional>

#include <Eigen/Core>

namespace epichead::fusion {

class Predictor;

struct CarriedOrientationNoise {
  // 1-sigma of the gyro bias left after the filter's estimate, rad/s (0.3 deg/s).
  double bias_sigma_radps = 0.005;
  // 1-sigma of the gyro's scale error: a share of the angle turned since.
  double scale_sigma = 0.01;
};

// The orientation at a time and its 1-sigma per axis.
struct OrientationPrior {
  Eigen::Matrix3d cam_R_obj = Eigen::Matrix3d::Identity();
  double sigma_rad = 0;
};

// How far a found pose may be turned from a carried orientation (deg): three of its sigmas, and
// the pose's own error beside them (refinement on one frame's edges leaves a far object's turn out
// of the image plane a few degrees off).
inline double carried_turn_tolerance_deg(const OrientationPrior& carried, double pose_turn_error_deg = 10.0) {
  return pose_turn_error_deg + 3 * carried.sigma_rad * 180 / std::numbers::pi;
}

class CarriedOrientation {
 public:
  // cam_R_imu: the IMU's mount (the gyro measures in the IMU frame).
  CarriedOrientation(const Eigen::Matrix3d& cam_R_imu, const CarriedOrientationNoise& noise);

  // The filter knew the orientation at t_s (camera clock) to sigma_rad, with this gyro bias.
  // Samples up to t_s are taken as already in it.
  void set(double t_s, const Eigen::Matrix3d& cam_R_obj, double sigma_rad, const Eigen::Vector3d& gyro_bias_radps);
  // The filter's orientation at t_s (just updated) and its gyro bias; the 1-sigma the largest of
  // its rotation block's, without a body of revolution's free turn (the filter's
  // gravity_check.free_turn_axis_obj), which no outline can contradict. Nothing happens before the
  // filter starts.
  void set_from(const Predictor& filter, double t_s);
  // One gyro reading at t_s (camera clock). A reading at or before the newest one taken (a clock
  // restart feeding samples again), or not finite, is skipped.
  void add_gyro(double t_s, const Eigen::Vector3d& gyro_radps);
  // The orientation at the newest reading, its sigma grown with the time and the turn since the
  // set; nothing before the first set(). Meant for a t_s just after the newest reading (a frame's
  // exposure): the few milliseconds between are not extrapolated.
  std::optional<OrientationPrior> at(double t_s) const;

 private:
  Eigen::Matrix3d cam_R_imu_;
  CarriedOrientationNoise noise_;
  bool known_ = false;
  Eigen::Matrix3d cam_R_obj_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d bias_radps_ = Eigen::Vector3d::Zero();
  double set_t_s_ = 0, sigma0_rad_ = 0;
  double last_t_s_ = 0;
  Eigen::Vector3d last_gyro_ = Eigen::Vector3d::Zero();
  bool have_last_ = false;
  double turned_rad_ = 0;  // the angle turned since the set, summed
};

}  // namespace epichead::fusion
