// A detected pose levelled to the measured up (geometry/level_to_up.h): the object's up along
// the camera's up afterwards, the model's centre where the image showed it, the turn about the up
// kept; nothing done without a usable up.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "epichead/geometry/level_to_up.h"

using epichead::geometry::level_to_up;

namespace {

constexpr double kDeg = M_PI / 180.0;

// The camera's up (-y) and the object's (+z).
struct Up {
  Eigen::Vector3d up_cam, up_obj;
};
const Up kUp{Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(0, 0, 1)};

double angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// A can-like object 0.5 m in front of the camera, its up (+z) along the camera's up (-y), turned
// 30 deg about that up; then tilted by tilt_deg about the camera's x axis.
Eigen::Isometry3d object_pose(double tilt_deg) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  const Eigen::Matrix3d upright = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();  // obj z -> cam -y
  p.linear() = Eigen::AngleAxisd(tilt_deg * kDeg, Eigen::Vector3d::UnitX()) * upright *
               Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(0.02, 0.05, 0.5);
  return p;
}

}  // namespace

TEST_CASE("level_to_up: a detection tilted 9 deg is turned upright about the model's centre, its heading kept") {
  const Up up = kUp;
  const Eigen::Vector3d centre(0, 0, 0.06);
  const Eigen::Isometry3d tilted = object_pose(9);
  REQUIRE(angle(tilted.linear() * up.up_obj, up.up_cam) == Approx(9 * kDeg));
  const Eigen::Isometry3d level = level_to_up(tilted, up.up_obj, up.up_cam, centre);
  CHECK(angle(level.linear() * up.up_obj, up.up_cam) < 1e-9);
  CHECK(((level * centre) - (tilted * centre)).norm() < 1e-12);
  // The turn about the up: the object's x seen from the camera, across the up, as the untilted pose has it.
  const auto heading = [&](const Eigen::Isometry3d& p) {
    const Eigen::Vector3d x = p.linear() * Eigen::Vector3d::UnitX();
    return Eigen::Vector3d(x - x.dot(up.up_cam) * up.up_cam).normalized();
  };
  CHECK(angle(heading(level), heading(object_pose(0))) < 0.5 * kDeg);
}

TEST_CASE("level_to_up: an upright pose is kept, and a non-finite up changes nothing") {
  const Up up = kUp;
  const Eigen::Isometry3d upright = object_pose(0);
  CHECK(level_to_up(upright, up.up_obj, up.up_cam, Eigen::Vector3d::Zero()).isApprox(upright, 1e-12));
  const Eigen::Vector3d broken = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const Eigen::Isometry3d tilted = object_pose(9);
  CHECK(level_to_up(tilted, up.up_obj, broken, Eigen::Vector3d::Zero()).isApprox(tilted, 0.0));
  CHECK(level_to_up(tilted, up.up_obj, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()).isApprox(tilted, 0.0));
}
