// The pose solver's per-edgel values of a line (pose_terms.h: line_edgel_values), element-wise so
// that the loop vectorises; the solver sums them afterwards in edgel order.
#include <cmath>

#include "avx2_clone.h"
#include "pose_terms.h"

namespace epichead::vision::detail {

namespace {

// Built without trapping maths (vision/CMakeLists.txt), so that GCC computes both sides of
// Tukey's cut and selects, which it must to vectorise: a floating-point exception flag is the
// only thing that can differ, and nothing reads them.
//
// xy: n (x, y) pairs. Each value is the one-loop definition's Eigen expression (the residual,
// Tukey, dr/dl; tests/vision/test_pose_terms.cpp), written out term by term in the order Eigen
// evaluates them: l . (x, y, 1) is
// (lx x + ly y) + lz, and dr/dl = (x / s - ldx / (s s s) (lx, ly, 0)) focal / sigma.
EPICHEAD_AVX2_CLONE void edgel_values(const double* __restrict xy, int n, double lx, double ly, double lz, double s,
                                      double focal, double sigma, bool with_cost, bool with_derivatives, double c,
                                      double rho_max, double* __restrict r, double* __restrict w, double* __restrict rho,
                                      double* __restrict d0, double* __restrict d1, double* __restrict d2) {
  for (int q = 0; q < n; ++q) {
    const double x = xy[2 * q], y = xy[2 * q + 1];
    const double ldx = lx * x + ly * y + lz * 1.0;
    r[q] = focal * ldx / s / sigma;
  }
  if (with_cost)
    for (int q = 0; q < n; ++q) {
      const double t = 1 - (r[q] / c) * (r[q] / c);
      const double inside = rho_max * (1 - t * t * t);  // computed for every edgel: a select, not a branch
      rho[q] = std::abs(r[q]) >= c ? rho_max : inside;
    }
  if (!with_derivatives) return;
  const double s3 = s * s * s;
  for (int q = 0; q < n; ++q) {
    const double x = xy[2 * q], y = xy[2 * q + 1];
    const double u = r[q] / c;
    const double t = 1 - u * u;
    const double inside = t * t;
    w[q] = std::abs(r[q]) >= c ? 0.0 : inside;
    const double k = (lx * x + ly * y + lz * 1.0) / s3;
    d0[q] = (x / s - k * lx) * focal / sigma;
    d1[q] = (y / s - k * ly) * focal / sigma;
    d2[q] = (1.0 / s - k * 0.0) * focal / sigma;
  }
}

}  // namespace

void line_edgel_values(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, int n, double focal,
                       const Tukey* k, bool with_derivatives, EdgelChunk& out) {
  static_assert(sizeof(Eigen::Vector2d) == 2 * sizeof(double), "edgels as packed (x, y) pairs");
  edgel_values(xns[0].data(), n, img.l.x(), img.l.y(), img.l.z(), img.s, focal, obs.sigma_px, k != nullptr,
               with_derivatives && k != nullptr, k ? k->c : 1.0, k ? k->rho_max : 0.0, out.r, out.w, out.rho, out.d0, out.d1,
               out.d2);
}

}  // namespace epichead::vision::detail
