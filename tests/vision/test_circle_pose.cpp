// Circle pose from an ellipse: both solutions of the two-fold ambiguity, the choice by the
// prior normal, the propagated covariance against a Monte Carlo spread, and bad input.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "epichead/vision/circle_pose.h"
#include "epichead/vision/ellipse_fit.h"

using namespace epichead::vision;

namespace {

Camera camera() { return Camera(640, 480, Intrinsics{600.0, 600.0, 320.0, 240.0}); }

struct Circle3d {
  Eigen::Vector3d centre, normal;
  double radius;
  Eigen::Vector3d point(double t) const {
    const Eigen::Vector3d a = normal.unitOrthogonal(), b = normal.cross(a);
    return centre + radius * (std::cos(t) * a + std::sin(t) * b);
  }
};

// The circle's image points, optionally with pixel noise, and the exact direct fit to them.
std::vector<Eigen::Vector2d> image_points(const Circle3d& c, int n, double noise_px, std::mt19937& rng) {
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<Eigen::Vector2d> p;
  for (int i = 0; i < n; ++i) p.push_back(camera().project(c.point(2 * M_PI * i / n)) + Eigen::Vector2d(noise(rng), noise(rng)));
  return p;
}

Ellipse fit(const std::vector<Eigen::Vector2d>& p) {
  std::vector<double> x, y;
  for (const auto& q : p) { x.push_back(q.x()); y.push_back(q.y()); }
  auto e = fit_ellipse_direct(x.data(), y.data(), nullptr, static_cast<int>(p.size()));
  REQUIRE(e);
  return *e;
}

Circle3d tilted(double tilt_deg, const Eigen::Vector3d& centre, double radius) {
  // Normal toward the camera, tilted about an oblique axis.
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 0.4, 0).normalized();
  const Eigen::Vector3d n = Eigen::AngleAxisd(tilt_deg * M_PI / 180, axis) * Eigen::Vector3d(0, 0, -1);
  return {centre, n, radius};
}

}  // namespace

TEST_CASE("circle pose recovers centre and normal from an exact ellipse, the prior choosing the solution", "[circle_pose]") {
  std::mt19937 rng(1);
  for (double tilt : {20.0, 45.0, 70.0}) {
    for (const Eigen::Vector3d& centre : {Eigen::Vector3d(0.0, 0.0, 0.6), Eigen::Vector3d(0.12, -0.08, 0.8)}) {
      const Circle3d c = tilted(tilt, centre, 0.1);
      const Ellipse e = fit(image_points(c, 40, 0.0, rng));
      // A prior 10 deg off the true normal.
      const Eigen::Vector3d prior = Eigen::AngleAxisd(10 * M_PI / 180, Eigen::Vector3d::UnitY()) * c.normal;
      auto pose = circle_pose(e, camera(), 0.1, prior);
      REQUIRE(pose);
      INFO("tilt " << tilt << " centre " << centre.transpose());
      CHECK((pose->circle.centre_cam - c.centre).norm() < 1e-6);
      CHECK(pose->circle.normal_cam.dot(c.normal) > 1 - 1e-9);
      // The other solution is a different plane through the same image, same radius, same cone.
      CHECK(std::fabs(pose->other.normal_cam.dot(c.normal)) < 1 - 1e-4);
      CHECK(pose->ambiguity_rad > 0.01);
      CHECK(std::fabs((camera().project(pose->other.centre_cam) - camera().project(c.centre)).norm()) > 1e-3);
      // A prior near the other solution picks the other solution.
      auto flipped = circle_pose(e, camera(), 0.1, pose->other.normal_cam);
      REQUIRE(flipped);
      CHECK((flipped->circle.centre_cam - pose->other.centre_cam).norm() < 1e-9);
    }
  }
}

TEST_CASE("circle pose scales with the radius and keeps the centre in front of the camera", "[circle_pose]") {
  std::mt19937 rng(2);
  const Circle3d c = tilted(30, {0.05, 0.02, 0.5}, 0.07);
  const Ellipse e = fit(image_points(c, 30, 0.0, rng));
  auto half = circle_pose(e, camera(), 0.035, c.normal);
  REQUIRE(half);
  CHECK((half->circle.centre_cam - 0.5 * c.centre).norm() < 1e-6);
  CHECK(half->circle.centre_cam.z() > 0);
}

TEST_CASE("the propagated covariance matches the Monte Carlo spread of centre and normal", "[circle_pose]") {
  std::mt19937 rng(3);
  const Circle3d c = tilted(50, {0.03, 0.01, 0.7}, 0.1);
  const double sigma = 0.5;
  const Ellipse exact = fit(image_points(c, 40, 0.0, rng));
  const auto pts = image_points(c, 40, 0.0, rng);
  const auto cov_e = ellipse_covariance(exact, pts.data(), static_cast<int>(pts.size()), sigma);
  REQUIRE(cov_e);
  auto pose = circle_pose(exact, camera(), 0.1, c.normal, &*cov_e);
  REQUIRE(pose);
  // Empirical covariance over noisy fits.
  const int trials = 300;
  Eigen::Matrix<double, 6, 6> emp = Eigen::Matrix<double, 6, 6>::Zero();
  for (int k = 0; k < trials; ++k) {
    auto p = circle_pose(fit(image_points(c, 40, sigma, rng)  /* per axis: sigma along the normal too */), camera(), 0.1, c.normal);
    REQUIRE(p);
    Eigen::Matrix<double, 6, 1> d;
    d << p->circle.centre_cam - c.centre, p->circle.normal_cam - c.normal;
    emp += d * d.transpose() / trials;
  }
  for (int i = 0; i < 6; ++i) {
    INFO("component " << i << " predicted " << pose->covariance(i, i) << " observed " << emp(i, i));
    CHECK(pose->covariance(i, i) > 0.6 * emp(i, i));
    CHECK(pose->covariance(i, i) < 1.6 * emp(i, i));
  }
}

TEST_CASE("circle pose rejects a bad radius, an invalid ellipse and a zero prior", "[circle_pose]") {
  Ellipse e;
  e.centre_px = {320, 240};
  e.semi_major_px = 50;
  e.semi_minor_px = 30;
  CHECK_FALSE(circle_pose(e, camera(), 0.0, Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(circle_pose(e, camera(), -1.0, Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(circle_pose(e, camera(), NAN, Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(circle_pose(e, camera(), 0.1, Eigen::Vector3d::Zero()));
  Ellipse bad = e;
  bad.semi_minor_px = 80;  // b > a
  CHECK_FALSE(circle_pose(bad, camera(), 0.1, Eigen::Vector3d::UnitZ()));
  CHECK_FALSE(ellipse_covariance(e, nullptr, 0, 1.0));
  const auto ok = circle_pose(e, camera(), 0.1, Eigen::Vector3d::UnitZ());
  REQUIRE(ok);
  CHECK(ok->circle.centre_cam.allFinite());
}
