// Ellipse value type, the direct least-squares fit and RANSAC with candidates: accuracy on
// exact, noisy and outlier-laden points, arcs, several candidates, and garbage input.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "epichead/vision/ellipse.h"
#include "epichead/vision/ellipse_fit.h"

using namespace epichead::vision;

namespace {

Ellipse make(double cx, double cy, double a, double b, double angle) {
  Ellipse e;
  e.centre_px = {cx, cy};
  e.semi_major_px = a;
  e.semi_minor_px = b;
  e.angle_rad = angle;
  return e;
}

// Axis angle difference modulo pi (an ellipse turned by pi is the same ellipse).
double angle_diff(double a, double b) {
  const double d = std::remainder(a - b, M_PI);
  return std::fabs(d);
}

struct Points {
  std::vector<double> x, y;
  std::vector<int> group;
  void add(const Eigen::Vector2d& p, int g) { x.push_back(p.x()); y.push_back(p.y()); group.push_back(g); }
  int n() const { return static_cast<int>(x.size()); }
};

// n points spread over parametric angles [t0, t0 + span) with Gaussian noise along the normal.
Points on_ellipse(const Ellipse& e, int n, double noise_px, std::mt19937& rng, double t0 = 0, double span = 2 * M_PI) {
  std::normal_distribution<double> noise(0.0, noise_px);
  Points p;
  for (int i = 0; i < n; ++i) {
    const double t = t0 + span * i / n;
    p.add(e.point(t) + noise(rng) * e.outward_normal(t), i);
  }
  return p;
}

}  // namespace

TEST_CASE("an ellipse survives the round trip through its conic", "[ellipse]") {
  for (double angle : {0.0, 0.4, -1.2, 1.5}) {
    const Ellipse e = make(320.5, 211.0, 90.0, 35.0, angle);
    const auto back = Ellipse::from_conic(e.conic());
    REQUIRE(back);
    CHECK((back->centre_px - e.centre_px).norm() < 1e-6);
    CHECK(back->semi_major_px == Approx(90.0).epsilon(1e-9));
    CHECK(back->semi_minor_px == Approx(35.0).epsilon(1e-9));
    CHECK(angle_diff(back->angle_rad, angle) < 1e-9);
    // Points of the parametric form lie on the conic; normals point away from the centre.
    for (double t : {0.0, 1.0, 2.5, 4.0}) {
      CHECK(e.distance(e.point(t)) < 1e-9);
      CHECK(e.outward_normal(t).dot(e.point(t) - e.centre_px) > 0);
      CHECK(std::fabs(wrap_angle(e.param_of_polar(e.polar_of_param(t)) - t)) < 1e-9);
    }
    // Sampson distance of a point 2 px outside is about 2 px.
    CHECK(e.distance(e.point(0.7) + 2.0 * e.outward_normal(0.7)) == Approx(2.0).margin(0.1));
  }
}

TEST_CASE("hyperbolas, parabolas and imaginary conics are no ellipse", "[ellipse]") {
  Conic hyperbola, parabola, imaginary, nan;
  hyperbola << 1, 0, -1, 0, 0, -1;
  parabola << 1, 0, 0, 0, -1, 0;
  imaginary << 1, 0, 1, 0, 0, 1;
  nan << std::numeric_limits<double>::quiet_NaN(), 0, 1, 0, 0, -1;
  CHECK_FALSE(Ellipse::from_conic(hyperbola));
  CHECK_FALSE(Ellipse::from_conic(parabola));
  CHECK_FALSE(Ellipse::from_conic(imaginary));
  CHECK_FALSE(Ellipse::from_conic(nan));
  CHECK_FALSE(Ellipse::from_conic(Conic::Zero()));
}

TEST_CASE("the direct fit recovers an ellipse from exact points, also from a 90 degree arc", "[ellipse_fit]") {
  std::mt19937 rng(1);
  const Ellipse truth = make(400.0, 300.0, 120.0, 45.0, 0.7);
  for (double span : {2 * M_PI, M_PI / 2}) {
    const Points p = on_ellipse(truth, 30, 0.0, rng, 0.3, span);
    const auto fit = fit_ellipse_direct(p.x.data(), p.y.data(), nullptr, p.n());
    REQUIRE(fit);
    CHECK((fit->centre_px - truth.centre_px).norm() < 1e-6);
    CHECK(fit->semi_major_px == Approx(120.0).epsilon(1e-8));
    CHECK(fit->semi_minor_px == Approx(45.0).epsilon(1e-8));
    CHECK(angle_diff(fit->angle_rad, 0.7) < 1e-8);
  }
}

TEST_CASE("the direct fit agrees with OpenCV's fitEllipseDirect on noisy points", "[ellipse_fit]") {
  std::mt19937 rng(7);
  const Ellipse truth = make(250.0, 180.0, 70.0, 50.0, -0.3);
  const Points p = on_ellipse(truth, 40, 1.0, rng);
  std::vector<cv::Point2f> cv_points;
  for (int i = 0; i < p.n(); ++i) cv_points.emplace_back(static_cast<float>(p.x[i]), static_cast<float>(p.y[i]));
  const cv::RotatedRect ref = cv::fitEllipseDirect(cv_points);
  const auto fit = fit_ellipse_direct(p.x.data(), p.y.data(), nullptr, p.n());
  REQUIRE(fit);
  CHECK(fit->centre_px.x() == Approx(ref.center.x).margin(0.02));
  CHECK(fit->centre_px.y() == Approx(ref.center.y).margin(0.02));
  CHECK(2 * fit->semi_major_px == Approx(std::max(ref.size.width, ref.size.height)).margin(0.05));
  CHECK(2 * fit->semi_minor_px == Approx(std::min(ref.size.width, ref.size.height)).margin(0.05));
}

TEST_CASE("RANSAC fits an ellipse to noisy points with 50% outliers to sub-pixel accuracy", "[ellipse_fit]") {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    std::mt19937 rng(seed);
    const Ellipse truth = make(300.0 + seed, 240.0, 110.0, 60.0, 0.2 * seed);
    Points p = on_ellipse(truth, 60, 0.4, rng);
    std::uniform_real_distribution<double> ux(170, 430), uy(110, 370);
    for (int i = 0; i < 60; ++i) p.add({ux(rng), uy(rng)}, i);  // outliers share the tracker lines
    EllipseRansac ransac;
    REQUIRE(ransac.fit(p.x.data(), p.y.data(), p.group.data(), p.n()) >= 1);
    const EllipseFit& best = ransac.candidates().front();
    INFO("seed " << seed);
    CHECK((best.ellipse.centre_px - truth.centre_px).norm() < 0.5);
    CHECK(best.ellipse.semi_major_px == Approx(110.0).margin(0.5));
    CHECK(best.ellipse.semi_minor_px == Approx(60.0).margin(0.5));
    CHECK(angle_diff(best.ellipse.angle_rad, truth.angle_rad) < 0.02);
    // Nearly all true points are inliers and few outliers are.
    int true_inliers = 0;
    for (int k = 0; k < best.support; ++k) true_inliers += ransac.inliers()[best.inlier_begin + k] < 60;
    CHECK(true_inliers >= 55);
    CHECK(best.support - true_inliers <= 8);
  }
}

TEST_CASE("RANSAC keeps two concentric ellipses of equal support as two candidates", "[ellipse_fit]") {
  std::mt19937 rng(3);
  const Ellipse inner = make(200.0, 200.0, 80.0, 50.0, 0.0), outer = make(200.0, 200.0, 88.0, 58.0, 0.0);
  Points p = on_ellipse(inner, 40, 0.2, rng);
  const Points q = on_ellipse(outer, 40, 0.2, rng);
  for (int i = 0; i < q.n(); ++i) p.add({q.x[i], q.y[i]}, i);
  EllipseRansac ransac;
  REQUIRE(ransac.fit(p.x.data(), p.y.data(), p.group.data(), p.n()) == 2);
  double a0 = ransac.candidates()[0].ellipse.semi_major_px, a1 = ransac.candidates()[1].ellipse.semi_major_px;
  if (a0 > a1) std::swap(a0, a1);
  CHECK(a0 == Approx(80.0).margin(0.5));
  CHECK(a1 == Approx(88.0).margin(0.5));
  // With one candidate wanted, only the best comes out.
  ransac.options().max_candidates = 1;
  CHECK(ransac.fit(p.x.data(), p.y.data(), p.group.data(), p.n()) == 1);
}

TEST_CASE("RANSAC gives no candidate for too few, collinear or non-finite points", "[ellipse_fit]") {
  EllipseRansac ransac;
  std::vector<double> x{1, 2, 3, 4}, y{1, 2, 3, 4};
  CHECK(ransac.fit(x.data(), y.data(), nullptr, 4) == 0);
  x = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  y = {0, 2, 4, 6, 8, 10, 12, 14, 16, 18};
  CHECK(ransac.fit(x.data(), y.data(), nullptr, 10) == 0);
  CHECK_FALSE(fit_ellipse_direct(x.data(), y.data(), nullptr, 10));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> xn(20, nan), yn(20, 1.0);
  CHECK(ransac.fit(xn.data(), yn.data(), nullptr, 20) == 0);
  CHECK_FALSE(fit_ellipse_direct(xn.data(), yn.data(), nullptr, 20));
}

TEST_CASE("two arcs overlap on the longest piece both cover, across the wrap at pi", "[ellipse]") {
  using epichead::vision::EllipseArc;
  const EllipseArc full{};
  const EllipseArc a{2.5, 2.0};  // 2.5 .. 4.5 rad, across +-pi
  auto same = [](const std::optional<EllipseArc>& x, double begin, double span) {
    REQUIRE(x.has_value());
    CHECK(std::remainder(x->begin_rad - begin, 2 * M_PI) == Approx(0).margin(1e-12));
    CHECK(x->span_rad == Approx(span));
  };
  same(EllipseArc::overlap(full, a), 2.5, 2.0);
  same(EllipseArc::overlap(a, full), 2.5, 2.0);
  same(EllipseArc::overlap(a, EllipseArc{-2.0, 1.0}), -2.0 + 2 * M_PI, 4.5 - (-2.0 + 2 * M_PI));
  same(EllipseArc::overlap(a, EllipseArc{3.0, 0.5}), 3.0, 0.5);  // inside
  CHECK_FALSE(EllipseArc::overlap(a, EllipseArc{0.0, 1.0}).has_value());
  // Two pieces (b runs from inside a round the circle into a again): the longer one.
  same(EllipseArc::overlap(a, EllipseArc{4.2, 6.0}), 2.5, 4.2 + 6.0 - 2 * M_PI - 2.5);
}
