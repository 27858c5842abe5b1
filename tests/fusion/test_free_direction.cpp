// A direction vision does not measure (fusion/free_direction.h): a body of revolution's turn about
// its axis, given a 1-rad sigma by the pose estimator. It is found in the covariance (and a pose
// whose depth alone is loose is not taken for it); an update compares the other five directions
// only, so a pose turned anywhere about the axis neither pulls nor gates; and a filter started from
// such a pose holds the turn to kFreeTurnStartSigmaRad, so that the next poses, whose free
// directions differ a little from the first one's, do not throw its pose off.
#include <catch2/catch.hpp>

#include "epichead/fusion/free_direction.h"
#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

// The left perturbation (translation, rotation) of cam_T_obj for a 1-rad turn of the object about
// its own axis `axis_obj` through its origin.
Vector6d turn_twist(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& axis_obj) {
  const Eigen::Vector3d w = cam_T_obj.linear() * axis_obj.normalized();
  Vector6d u;
  u << -w.cross(cam_T_obj.translation()), w;
  return u;
}

// What the pose estimator gives a body of revolution: 1 mm and 0.1 deg on the measured
// directions, 1 rad on the turn.
Matrix6d free_turn_cov(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& axis_obj) {
  const Vector6d u = turn_twist(cam_T_obj, axis_obj);
  return pose_cov(1e-3, 0.1 * M_PI / 180) + u * u.transpose();
}

const Eigen::Vector3d kAxisObj(0.1, 0.95, 0.2);  // the trajectory's up: a can standing upright

}  // namespace

TEST_CASE("free direction: a body of revolution's turn is found, a loose depth is not") {
  Trajectory traj;
  const Eigen::Isometry3d pose = traj.at(0.3).x.cam_T_obj();
  const auto free = find_free_direction(free_turn_cov(pose, kAxisObj));
  REQUIRE(free);
  CHECK(free->turn_sigma_rad == Approx(1.0).epsilon(0.01));
  const Vector6d u = turn_twist(pose, kAxisObj).normalized();
  CHECK(std::abs(free->direction.dot(u)) > 0.9999);
  // Depth loose to 10 cm, the rest tight: large, but a slide, not a turn.
  Matrix6d depth = pose_cov(1e-3, 1e-3);
  depth(2, 2) = 0.01;
  CHECK_FALSE(find_free_direction(depth));
  CHECK_FALSE(find_free_direction(pose_cov(3e-3, 4e-3)));
  // A filter starts from it with the turn at kFreeTurnStartSigmaRad and the rest unchanged.
  const Matrix6d start = start_covariance(free_turn_cov(pose, kAxisObj));
  const auto fixed = find_free_direction(start);
  CHECK_FALSE(fixed);  // 0.05 rad is no longer free
  const double turn_var = u.dot(start * u) * u.tail<3>().squaredNorm();  // u = the unit twist: a turn of 1 / |u_rot| rad
  CHECK(std::sqrt(turn_var) == Approx(kFreeTurnStartSigmaRad).epsilon(0.05));
}

TEST_CASE("free direction: a pose turned about the free axis is applied without pulling the filter's turn") {
  Trajectory traj;
  ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 1.0, 5);
  auto p = Predictor::create(PredictorOptions{});
  REQUIRE(p);
  std::size_t next = 0;
  const auto feed_until = [&](double t_s) {
    for (; next < imu.samples.size() && imu.samples[next].t_s <= t_s + 1e-9; ++next) p->add_imu(imu.samples[next]);
  };
  // Started from the truth with the turn free, then poses at 30 Hz from the truth, each turned about
  // the axis by a different angle (the pose estimator leaves the turn wherever its prediction was).
  feed_until(0.2);
  const Eigen::Isometry3d first = traj.at(0.2).x.cam_T_obj();
  REQUIRE(p->add_vision(0.2, first, free_turn_cov(first, kAxisObj)).verdict == VisionVerdict::Initialised);
  for (int k = 1; k <= 8; ++k) {
    const double t = 0.2 + k / 30.0;
    feed_until(t + 0.001);
    const Eigen::Isometry3d truth = traj.at(t).x.cam_T_obj();
    const double turn_rad = (k % 2 ? 1 : -1) * 0.05 * k;
    Eigen::Isometry3d turned = truth;
    turned.linear() = truth.linear() * Eigen::AngleAxisd(turn_rad, kAxisObj.normalized()).toRotationMatrix();
    turned.translation() = truth.translation();  // a turn about the axis through the object's origin
    const VisionResult r = p->add_vision(t, turned, free_turn_cov(turned, kAxisObj));
    INFO("frame " << k << " turned " << turn_rad << " rad");
    CHECK(r.verdict == VisionVerdict::Applied);
    CHECK(r.dims == 5);
    CHECK(r.mahalanobis2 < 20);
    // The filter's pose stays on the truth: its turn is the first pose's, carried by the gyro.
    const auto pred = p->predict(t);
    REQUIRE(pred);
    CHECK((pred->cam_T_obj.translation() - truth.translation()).norm() < 2e-3);
    CHECK(Eigen::AngleAxisd(pred->cam_T_obj.linear() * truth.linear().transpose()).angle() < 0.2 * M_PI / 180);
  }
}
