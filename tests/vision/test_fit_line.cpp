// Line fitting: total least squares, RANSAC with Eq. 4 iterations, several candidates.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "epichead/vision/fit_line.h"

using namespace epichead::vision;

namespace {

struct Points {
  std::vector<float> x, s;
  void add(float xv, float sv) { x.push_back(xv); s.push_back(sv); }
  int n() const { return static_cast<int>(x.size()); }
};

}  // namespace

TEST_CASE("total least squares recovers a slanted line exactly from exact points", "[fit_line]") {
  Points p;
  for (int i = 0; i < 30; ++i) p.add(0.3f * i - 2.0f, static_cast<float>(i));
  std::vector<int> idx(p.n());
  for (int i = 0; i < p.n(); ++i) idx[i] = i;
  const WindowLine l = fit_line_tls(p.x.data(), p.s.data(), idx.data(), p.n());
  CHECK(l.m == Approx(0.3f).margin(1e-4));
  CHECK(l.c == Approx(-2.0f).margin(1e-3));
}

TEST_CASE("total least squares minimises perpendicular, not horizontal, distances", "[fit_line]") {
  // Pairs of points +-1 px from x = 0.5 s along its normal: the perpendicular residuals are
  // symmetric, so TLS returns the line exactly, while regressing x on s would not (the pairs
  // are offset along s too, which biases an ordinary least-squares slope).
  Points p;
  const float nx = 1.0f / std::sqrt(1.25f), ns = -0.5f / std::sqrt(1.25f);  // unit normal of x = 0.5 s
  for (int i = 0; i < 20; ++i) {
    const float t = static_cast<float>(i);
    for (float d : {-1.0f, 1.0f}) p.add(0.5f * t + d * nx, t + d * ns);  // a pair at +-1 px from the line
  }
  std::vector<int> idx(p.n());
  for (int i = 0; i < p.n(); ++i) idx[i] = i;
  const WindowLine l = fit_line_tls(p.x.data(), p.s.data(), idx.data(), p.n());
  CHECK(l.m == Approx(0.5f).margin(2e-3));
}

TEST_CASE("RANSAC finds the line among 40 percent outliers and refines it on its inliers", "[fit_line]") {
  Points p;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ux(-20, 20);
  std::normal_distribution<float> noise(0, 0.2f);
  for (int i = 0; i < 40; ++i) {
    if (i % 5 < 2) p.add(ux(rng), static_cast<float>(i));  // outliers
    else p.add(1.5f - 0.1f * i + noise(rng), static_cast<float>(i));
  }
  LineRansac ransac;
  REQUIRE(ransac.fit(p.x.data(), p.s.data(), p.n(), 0, 39) >= 1);
  const LineFit& best = ransac.candidates().front();
  CHECK(best.line.m == Approx(-0.1f).margin(0.02));
  CHECK(best.line.x_at(20) == Approx(1.5f - 2.0f).margin(0.2));
  CHECK(best.support >= 22);
  CHECK(best.support <= 26);
}

TEST_CASE("Eq. 4 sets the iteration count from the inlier ratio", "[fit_line]") {
  Points p;
  for (int i = 0; i < 30; ++i) p.add(0.0f, static_cast<float>(i));  // all inliers: w = 1
  RansacOptions single;
  single.max_candidates = 1;
  LineRansac r1(single);
  REQUIRE(r1.fit(p.x.data(), p.s.data(), p.n(), 0, 29) == 1);
  CHECK(r1.iterations() == 1);  // w = 1: one sample is certain
  // Several candidates: Eq. 4 with w = keep_ratio = 0.7: ceil(log(0.01) / log(1 - 0.49)) = 7.
  LineRansac r2;
  REQUIRE(r2.fit(p.x.data(), p.s.data(), p.n(), 0, 29) == 1);
  CHECK(r2.iterations() == static_cast<int>(std::ceil(std::log(0.01) / std::log(1 - 0.49))));
  // Half the points are outliers: far more iterations are needed.
  Points q;
  for (int i = 0; i < 30; ++i) q.add(i % 2 ? 0.0f : 10.0f * std::sin(1.7f * i), static_cast<float>(i));
  LineRansac r3(single);
  REQUIRE(r3.fit(q.x.data(), q.s.data(), q.n(), 0, 29) >= 1);
  const double w = static_cast<double>(r3.candidates().front().support) / q.n();
  CHECK(w < 0.7);
  CHECK(r3.iterations() == static_cast<int>(std::ceil(std::log(0.01) / std::log(1 - w * w))));
  CHECK(r3.iterations() > 8);
}

TEST_CASE("two close parallel lines with similar support give two candidates, single mode one", "[fit_line]") {
  Points p;
  for (int i = 0; i < 30; ++i) {
    p.add(-1.5f, static_cast<float>(i));
    if (i % 10 != 0) p.add(1.5f, static_cast<float>(i) + 0.5f);  // slightly weaker
  }
  LineRansac multi;
  REQUIRE(multi.fit(p.x.data(), p.s.data(), p.n(), 0, 30) == 2);
  CHECK(multi.candidates()[0].line.c == Approx(-1.5f).margin(0.05));
  CHECK(multi.candidates()[1].line.c == Approx(1.5f).margin(0.05));
  CHECK(multi.candidates()[0].support == 30);
  CHECK(multi.candidates()[1].support == 27);
  // Each candidate's inliers are its own points.
  for (const LineFit& f : multi.candidates())
    for (int k = 0; k < f.support; ++k) CHECK(std::abs(p.x[multi.inliers()[f.inlier_begin + k]] - f.line.c) < 0.1f);
  RansacOptions single;
  single.max_candidates = 1;
  LineRansac one(single);
  CHECK(one.fit(p.x.data(), p.s.data(), p.n(), 0, 30) == 1);
}

TEST_CASE("a much weaker line is not kept as a candidate", "[fit_line]") {
  Points p;
  for (int i = 0; i < 30; ++i) {
    p.add(-4.0f, static_cast<float>(i));
    if (i % 3 == 0) p.add(4.0f, static_cast<float>(i) + 0.5f);  // a third of the support
  }
  LineRansac ransac;
  REQUIRE(ransac.fit(p.x.data(), p.s.data(), p.n(), 0, 30) == 1);
  CHECK(ransac.candidates()[0].line.c == Approx(-4.0f).margin(0.05));
}

TEST_CASE("RANSAC returns nothing for too few or degenerate points", "[fit_line]") {
  Points p;
  LineRansac ransac;
  CHECK(ransac.fit(p.x.data(), p.s.data(), 0, 0, 1) == 0);
  p.add(1, 1);
  p.add(2, 2);
  CHECK(ransac.fit(p.x.data(), p.s.data(), p.n(), 0, 2) == 0);  // below min_support
  Points row;  // all on one row: no near-vertical line
  for (int i = 0; i < 10; ++i) row.add(static_cast<float>(i), 5.0f);
  CHECK(ransac.fit(row.x.data(), row.s.data(), row.n(), 0, 10) == 0);
}
