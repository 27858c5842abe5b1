// The vision poses extrapolated alone (vision/constant_velocity.h): a steady turn and slide is
// carried on at its rate, a degraded pose is a start without motion, and a loss goes back to the
// last pose the image fully supported.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "epichead/geometry/se3.h"
#include "epichead/vision/constant_velocity.h"

using namespace epichead::vision;
namespace geometry = epichead::geometry;

namespace {

// The camera's motion between frames 0.1 s apart: the same step D each frame (0.05 rad about an
// axis, 2 cm along x), from a start 0.5 m in front: pose(k) = D^k start.
Eigen::Isometry3d step() {
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  d.translation() = Eigen::Vector3d(0.02, 0, 0);
  return d;
}

Eigen::Isometry3d pose_at(double t_s) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.translation() = Eigen::Vector3d(0.01, -0.02, 0.5);
  for (int k = 0; k < static_cast<int>(std::lround(t_s / 0.1)); ++k) p = step() * p;
  return p;
}

double distance(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return geometry::se3_log(a * b.inverse()).norm();
}

}  // namespace

TEST_CASE("constant velocity carries a steady turn and slide on to later frames") {
  ConstantVelocity cv(0.0, pose_at(0.0));
  CHECK(distance(cv.predict(0.1), pose_at(0.0)) < 1e-12);  // at rest until a second pose
  cv.observe(0.0, TrackStatus::Tracked, pose_at(0.0));
  cv.observe(0.1, TrackStatus::Tracked, pose_at(0.1));
  // One frame on, the step between the two poses is the motion's: it lands on the path again.
  CHECK(distance(cv.predict(0.2), pose_at(0.2)) < 1e-9);
  CHECK(distance(cv.predict(0.1), pose_at(0.1)) < 1e-12);
  // Half a frame on: half the turn and half the slide, within a millimetre of the screw motion's
  // halfway pose (the slide is taken straight, not along the screw).
  const Eigen::Isometry3d halfway = geometry::se3_exp(0.5 * geometry::se3_log(step())) * pose_at(0.1);
  CHECK(distance(cv.predict(0.15), halfway) < 1e-3);
  CHECK(distance(cv.predict(0.15), pose_at(0.1)) > 0.02);
}

TEST_CASE("constant velocity starts a degraded pose without motion and goes back to the last tracked pose after a loss") {
  ConstantVelocity cv(0.0, pose_at(0.0));
  cv.observe(0.0, TrackStatus::Tracked, pose_at(0.0));
  cv.observe(0.1, TrackStatus::Tracked, pose_at(0.1));
  // A doubtful pose: where the next frame starts, no velocity taken from it.
  Eigen::Isometry3d off = pose_at(0.2);
  off.translation().x() += 0.03;
  cv.observe(0.2, TrackStatus::Degraded, off);
  CHECK(distance(cv.predict(0.3), off) < 1e-12);
  // Lost: back to the last tracked pose (0.1 s), still without motion.
  cv.observe(0.3, TrackStatus::Lost, pose_at(0.3));
  CHECK(distance(cv.predict(0.4), pose_at(0.1)) < 1e-12);
  // A restart forgets the motion too.
  cv.observe(0.4, TrackStatus::Tracked, pose_at(0.4));
  cv.observe(0.5, TrackStatus::Tracked, pose_at(0.5));
  cv.restart(0.5, pose_at(0.0));
  CHECK(distance(cv.predict(0.6), pose_at(0.0)) < 1e-12);
}
