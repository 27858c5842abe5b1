// Whether gated vision poses agree with each other (fusion/gated_agreement.h): three gated poses
// that say the filter is off by the same error restart it, with applied poses between them or
// not; gated poses that scatter (outliers), or that are too far apart in time, do not.
#include <catch2/catch.hpp>

#include <random>

#include "epichead/fusion/gated_agreement.h"

using epichead::geometry::Matrix6d;
using epichead::geometry::Vector6d;
using epichead::fusion::GatedAgreement;

namespace {

// A pose's covariance: 2 mm and 0.5 deg 1-sigma.
Matrix6d pose_cov() {
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << 4e-6, 4e-6, 4e-6, 7.6e-5, 7.6e-5, 7.6e-5;
  return c;
}

// The innovation of a right pose against a filter tilted 7 deg about x and 15 mm off in y.
Vector6d filter_off() {
  Vector6d r;
  r << 0, 0.015, 0, 0.122, 0, 0;
  return r;
}

}  // namespace

TEST_CASE("gated agreement: three gated poses with one innovation restart the filter, applied ones between or not") {
  GatedAgreement g;
  const double dt = 1.0 / 30;
  Vector6d small;  // each pose's own noise, well within its covariance
  small << 0.001, -0.001, 0.0005, 0.004, -0.003, 0.002;
  CHECK_FALSE(g.add(0 * dt, filter_off(), pose_cov()));
  // Frame 1 was applied (a lock the filter agrees with): it is not passed here.
  CHECK_FALSE(g.add(2 * dt, filter_off() + small, pose_cov()));
  CHECK(g.add(4 * dt, filter_off() - small, pose_cov()));
  g.clear();
  CHECK_FALSE(g.add(5 * dt, filter_off(), pose_cov()));
}

TEST_CASE("gated agreement: outliers that scatter never restart the filter") {
  GatedAgreement g;
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0, 1);
  int restarts = 0;
  for (int k = 0; k < 300; ++k) {
    // Each a gross error of its own: 10-20 mm and 5-10 deg in random directions.
    Vector6d r;
    for (int i = 0; i < 6; ++i) r[i] = n(rng) * (i < 3 ? 0.015 : 0.13);
    restarts += g.add(k / 30.0, r, pose_cov());
  }
  CHECK(restarts == 0);
}

TEST_CASE("gated agreement: agreeing poses too far apart in time do not count") {
  GatedAgreement g;  // window 0.4 s
  CHECK_FALSE(g.add(0.0, filter_off(), pose_cov()));
  CHECK_FALSE(g.add(0.5, filter_off(), pose_cov()));
  CHECK_FALSE(g.add(1.0, filter_off(), pose_cov()));
  CHECK_FALSE(g.add(1.3, filter_off(), pose_cov()));  // 0.5 s is 0.8 s old: only 1.0 s counts
  CHECK(g.add(1.35, filter_off(), pose_cov()));       // 1.0, 1.3 and 1.35 s
}

TEST_CASE("gated agreement: a pose whose covariance says it constrains nothing along the error agrees with any") {
  // A body of revolution's turn about its axis: 1 rad 1-sigma there. Two poses that differ only
  // in that turn agree.
  GatedAgreement g;
  Matrix6d c = pose_cov();
  c(5, 5) = 1.0;
  Vector6d a = filter_off(), b = filter_off();
  a[5] = 0.5;
  b[5] = -0.4;
  CHECK_FALSE(g.add(0.0, a, c));
  CHECK_FALSE(g.add(0.03, b, c));
  CHECK(g.add(0.06, a, c));
}
