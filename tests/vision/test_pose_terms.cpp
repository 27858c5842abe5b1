// The pose solver's line terms, computed element-wise over chunks of edgels and summed after
// (pose_terms.h), against their definition: one loop over the edgels with the Eigen expressions
// the solver used before. Bit for bit, since a tracking run can hinge on the last bit of a pose.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "epichead/geometry/so3.h"
#include "pose_terms.h"

using namespace epichead::vision;
using namespace epichead::vision::detail;

namespace {

// The definition of a line's residual: the edgel's signed distance from the line's image.
double line_residual(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d& xn, double focal) {
  return focal * img.l.dot(Eigen::Vector3d(xn.x(), xn.y(), 1)) / img.s / obs.sigma_px;
}

// The definition: per edgel, the residual, Tukey's weight and cost and dr/dl, summed as they come.
void reference_line_block(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                          const Tukey& k, NormalEquations& ne, Eigen::Matrix3d& M, Eigen::Vector3d& v) {
  const Eigen::Vector3d& l = img.l;
  const double s = img.s;
  M.setZero();
  v.setZero();
  for (std::size_t q = 0; q < obs.edgels_px.size(); ++q) {
    const double r = line_residual(obs, img, xns[q], focal);
    const double w = k.weight(r);
    ne.cost += k.rho(r);
    const Eigen::Vector3d x(xns[q].x(), xns[q].y(), 1);
    const double ldx = l.dot(x);
    const Eigen::Vector3d dr_dl = (x / s - ldx / (s * s * s) * Eigen::Vector3d(l.x(), l.y(), 0)) * focal / obs.sigma_px;
    M.noalias() += (w * dr_dl) * dr_dl.transpose();
    v += (w * r) * dr_dl;
    ne.wr2 += w * r * r;
    ne.wsum += w;
  }
  Eigen::Matrix<double, 3, 6> dl;
  dl.leftCols<3>() = epichead::geometry::skew(img.A - img.B);
  dl.rightCols<3>() = -epichead::geometry::skew(l);
  ne.H.noalias() += dl.transpose() * M * dl;
  ne.g.noalias() += dl.transpose() * v;
}

bool same_bits(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

}  // namespace

TEST_CASE("a line's terms computed element-wise equal their one-loop definition bit for bit", "[pose]") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  const double focal = 612.5;
  // 1 to 150 edgels: within one chunk, exactly one, and across several.
  for (int n : {2, 3, 17, kEdgelChunk - 1, kEdgelChunk, kEdgelChunk + 1, 150}) {
    LineObservation obs;
    obs.a_obj = Eigen::Vector3d(-0.1, 0.02 * u(rng), 0.01 * u(rng));
    obs.b_obj = Eigen::Vector3d(0.1, 0.03 * u(rng), 0.01 * u(rng));
    obs.sigma_px = 0.7 + 0.5 * (u(rng) + 1);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(0.3 * u(rng), Eigen::Vector3d(u(rng), u(rng), 1).normalized()).toRotationMatrix();
    pose.translation() = Eigen::Vector3d(0.05 * u(rng), 0.05 * u(rng), 0.6);
    const LineImage img = line_image(obs, pose);
    std::vector<Eigen::Vector2d> xns;
    for (int q = 0; q < n; ++q) {
      // Points near the line's image (inliers), far from it (beyond Tukey's cut), and one not finite.
      const double t = u(rng);
      const Eigen::Vector3d A = img.A / img.A.z(), B = img.B / img.B.z();
      Eigen::Vector2d p = (0.5 * (1 + t) * A + 0.5 * (1 - t) * B).head<2>();
      p += Eigen::Vector2d(u(rng), u(rng)) * (q % 5 == 0 ? 0.05 : 0.002);
      if (n == 150 && q == 77) p.x() = std::numeric_limits<double>::quiet_NaN();
      xns.push_back(p);
      obs.edgels_px.push_back(p);  // only their count matters here
    }
    CAPTURE(n);
    const Tukey kernel(4.685 * 1.3);
    // The values, chunk by chunk.
    EdgelChunk chunk;
    int mismatches = 0;
    for (int first = 0; first < n; first += kEdgelChunk) {
      const int m = std::min(kEdgelChunk, n - first);
      line_edgel_values(obs, img, xns.data() + first, m, focal, &kernel, true, chunk);
      for (int q = 0; q < m; ++q) {
        const Eigen::Vector2d& xn = xns[static_cast<std::size_t>(first + q)];
        const double r = line_residual(obs, img, xn, focal);
        const Eigen::Vector3d x(xn.x(), xn.y(), 1);
        const double s = img.s, ldx = img.l.dot(x);
        const Eigen::Vector3d dr_dl =
            (x / s - ldx / (s * s * s) * Eigen::Vector3d(img.l.x(), img.l.y(), 0)) * focal / obs.sigma_px;
        mismatches += !same_bits(chunk.r[q], r) + !same_bits(chunk.w[q], kernel.weight(r)) +
                      !same_bits(chunk.rho[q], kernel.rho(r)) + !same_bits(chunk.d0[q], dr_dl.x()) +
                      !same_bits(chunk.d1[q], dr_dl.y()) + !same_bits(chunk.d2[q], dr_dl.z());
      }
    }
    CHECK(mismatches == 0);
    // The sums.
    NormalEquations got, want;
    Eigen::Matrix3d M;
    Eigen::Vector3d v;
    add_line_block(obs, img, xns.data(), focal, kernel, got, -1);
    reference_line_block(obs, img, xns.data(), focal, kernel, want, M, v);
    if (n == 150) {
      CHECK(std::isnan(got.cost));  // a non-finite edgel reaches the sums
      CHECK(!got.H.allFinite());
      continue;
    }
    CHECK(got.H == want.H);
    CHECK(got.g == want.g);
    CHECK(got.cost == want.cost);
    CHECK(got.wr2 == want.wr2);
    CHECK(got.wsum == want.wsum);
    double cost = 0, want_cost = 0;
    add_line_cost(obs, img, xns.data(), focal, kernel, cost);
    for (const auto& xn : xns) want_cost += kernel.rho(line_residual(obs, img, xn, focal));
    CHECK(cost == want_cost);
  }
}
