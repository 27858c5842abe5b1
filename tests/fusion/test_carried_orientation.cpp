// The orientation the gyro carries across a loss (fusion/carried_orientation.h): it follows the
// camera's turn from the gyro alone, with a mounted IMU and a bias taken off, its sigma grows with
// the time and the turn, and bad readings do not move it.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "epichead/fusion/carried_orientation.h"
#include "epichead/geometry/so3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
using namespace epichead::fusion::testing;

namespace {

double turn_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) { return Eigen::AngleAxisd(a.transpose() * b).angle(); }

// Feeds the exact gyro readings (plus `bias` in the IMU frame) of the sinusoidal trajectory from
// t0 to t1 at 1 kHz.
void feed(CarriedOrientation& c, const Trajectory& traj, double t0, double t1, const Eigen::Vector3d& bias) {
  const Eigen::Matrix3d imu_R_cam = traj.params().cam_R_imu.transpose();
  for (int k = static_cast<int>(std::lround(t0 * 1000)); k <= static_cast<int>(std::lround(t1 * 1000)); ++k) {
    const double t = k / 1000.0;
    c.add_gyro(t, imu_R_cam * traj.at(t).gyro_cam_radps + bias);
  }
}

}  // namespace

TEST_CASE("the carried orientation follows the camera's turn from the gyro alone, mounted and biased") {
  TrajectoryParams params;
  params.cam_R_imu = epichead::geometry::so3_exp(Eigen::Vector3d(0.3, -1.2, 0.5));
  const Trajectory traj(params);
  const Eigen::Vector3d bias(0.01, -0.02, 0.015);
  CarriedOrientation c(params.cam_R_imu, CarriedOrientationNoise{});
  CHECK_FALSE(c.at(0.5).has_value());  // nothing before the filter knew it

  feed(c, traj, 0.0, 0.5, bias);
  const Eigen::Matrix3d cam_R_obj0 = traj.at(0.5).x.obj_R_cam.transpose();
  c.set(0.5, cam_R_obj0, 0.01, bias);
  feed(c, traj, 0.501, 3.0, bias);
  const auto carried = c.at(3.0);
  REQUIRE(carried.has_value());
  const Eigen::Matrix3d truth = traj.at(3.0).x.obj_R_cam.transpose();
  // The trajectory turns the camera by tens of degrees; carried exactly, the midpoint rule leaves
  // well under a tenth of a degree.
  CHECK(turn_between(cam_R_obj0, truth) > 10 * kDegRad);
  CHECK(turn_between(carried->cam_R_obj, truth) < 0.1 * kDegRad);
  // The sigma grew from the set one with the time (2.5 s at 0.005 rad/s) and the turn.
  CHECK(carried->sigma_rad > std::hypot(0.01, 0.005 * 2.5));
  CHECK(carried->sigma_rad < 0.1);

  // A bias the filter did not take off turns it away by about bias x time, which the sigma covers.
  CarriedOrientation unaware(params.cam_R_imu, CarriedOrientationNoise{.bias_sigma_radps = 0.03, .scale_sigma = 0.01});
  feed(unaware, traj, 0.0, 0.5, bias);
  unaware.set(0.5, cam_R_obj0, 0.01, Eigen::Vector3d::Zero());
  feed(unaware, traj, 0.501, 3.0, bias);
  const auto off = unaware.at(3.0);
  REQUIRE(off.has_value());
  const double off_rad = turn_between(off->cam_R_obj, truth);
  CHECK(off_rad > 0.5 * bias.norm() * 2.5);
  CHECK(off_rad < 3 * off->sigma_rad);
}

TEST_CASE("the carried orientation skips readings that are not finite or out of order") {
  CarriedOrientation c(Eigen::Matrix3d::Identity(), CarriedOrientationNoise{});
  c.set(0.0, Eigen::Matrix3d::Identity(), 0.0, Eigen::Vector3d::Zero());
  const Eigen::Vector3d w(0, 0, 1.0);  // 1 rad/s about the optical axis
  for (int k = 0; k <= 100; ++k) c.add_gyro(k / 1000.0, w);
  c.add_gyro(0.1005, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  c.add_gyro(0.05, Eigen::Vector3d(0, 0, 50.0));  // from before the newest: a clock fed again
  c.add_gyro(std::numeric_limits<double>::infinity(), w);
  const auto carried = c.at(0.1);
  REQUIRE(carried.has_value());
  CHECK(carried->cam_R_obj.allFinite());
  // 0.1 s at 1 rad/s, the object turning the other way in the camera's frame.
  CHECK(turn_between(carried->cam_R_obj, epichead::geometry::so3_exp(Eigen::Vector3d(0, 0, -0.1))) < 1e-9);
  // A set with a non-finite value is refused: the orientation stays as it was.
  c.set(0.1, Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN()), 0.0, Eigen::Vector3d::Zero());
  CHECK(c.at(0.1)->cam_R_obj.allFinite());
}
