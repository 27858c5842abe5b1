#pragma once
// What each feature kind supplies the pose solver, in the manner of DLR ICG's modalities: its
// residuals (normalised by its sigma, so that every kind mixes in one cost) and its block of the
// weighted normal equations. The solver (pose_estimator.cpp) only sums them.
//
// Residuals per kind, all at a pose cam_T_obj and under its left perturbation xi = (rho, phi):
//  - line: the signed distance of an edgel from the projected model line, in undistorted
//    normalised coordinates (where a 3D line stays straight) scaled to pixels by the focal length:
//    with l = A_cam x B_cam, r = l . x / |l_xy|;
//  - junction: the reprojection error of a model vertex, in pixels;
//  - ellipse point: the first-order geometric distance from the image conic of a model circle;
//  - 3D point: the difference of a model vertex from its measurement in the camera frame.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/geometry/se3.h"
#include "epichead/vision/camera.h"
#include "epichead/vision/pose_estimator.h"

namespace epichead::vision::detail {

using geometry::Matrix6d;
using geometry::Vector6d;
using RowJ = Eigen::Matrix<double, 1, 6>;

// Tukey's biweight at kernel width c: weight w(r) and cost rho(r) (rho_max = c^2 / 6 hoisted).
struct Tukey {
  explicit Tukey(double width) : c(width), rho_max(width * width / 6) {}
  double weight(double u) const {
    if (std::abs(u) >= c) return 0;
    const double t = 1 - (u / c) * (u / c);
    return t * t;
  }
  double rho(double r) const {
    if (std::abs(r) >= c) return rho_max;
    const double t = 1 - (r / c) * (r / c);
    return rho_max * (1 - t * t * t);
  }
  double c, rho_max;
};

// Weighted normal equations H = sum w J^T J, g = sum w J^T r, with sum w r^2, sum w and Tukey's
// cost sum rho(r), summed in the order the features are visited.
struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double wr2 = 0, wsum = 0, cost = 0;
  // With shared errors asked for (the final equations only): sum over lines of s^2 (a a' + b b'),
  // where a = sum w dr/dxi is what a shift of the whole line by one pixel does to the gradient,
  // b = sum w u dr/dxi what a turn of it does that moves its ends by one pixel (u in [-1, 1]
  // along the line), and s the line's shared error in pixels. The solution moves by H^-1 a per
  // pixel of shift: errors every edgel of a line shares (the model's, a blurred edge's) do not
  // average out over its edgels.
  Matrix6d shared = Matrix6d::Zero();
  // One residual row r with its Jacobian row J. No skip at w = 0: a non-finite row must reach H.
  void add_row(double r, const RowJ& J, const Tukey& k) {
    const double w = k.weight(r);
    H.noalias() += w * J.transpose() * J;
    g.noalias() += w * J.transpose() * r;
    wr2 += w * r * r;
    wsum += w;
    cost += k.rho(r);
  }
};

// ---- Lines.

// A model segment's image at a pose: end points A, B in the camera, l = A x B and s = |l_xy|.
struct LineImage {
  Eigen::Vector3d A, B, l;
  double s;
};

inline LineImage line_image(const LineObservation& obs, const Eigen::Isometry3d& cam_T_obj) {
  LineImage img;
  img.A = cam_T_obj * obs.a_obj;
  img.B = cam_T_obj * obs.b_obj;
  img.l = img.A.cross(img.B);
  img.s = std::hypot(img.l.x(), img.l.y());
  return img;
}

// A line's edgels are taken kEdgelChunk at a time: first each edgel's own values (residual,
// Tukey weight and cost, dr/dl), element-wise with no sums, so that the loop vectorises; then the
// sums, in edgel order. The residual is the signed distance r = focal l . (x, y, 1) / |l_xy| /
// sigma_px; the values are written term by term as the one-loop Eigen expressions evaluated
// them, so the totals are those of one loop doing both (tests/vision/test_pose_terms.cpp holds
// them to that definition, bit for bit).
inline constexpr int kEdgelChunk = 64;

struct EdgelChunk {
  alignas(32) double r[kEdgelChunk];
  alignas(32) double w[kEdgelChunk];    // Tukey weight (with_derivatives only)
  alignas(32) double rho[kEdgelChunk];  // Tukey cost (with a kernel only)
  alignas(32) double d0[kEdgelChunk], d1[kEdgelChunk], d2[kEdgelChunk];  // dr/dl (with_derivatives only)
};

// The values of n <= kEdgelChunk edgels xns of a line: residuals always; with `k`, the Tukey
// cost; with_derivatives (needs k), the weight and dr/dl too.
void line_edgel_values(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, int n, double focal,
                       const Tukey* k, bool with_derivatives, EdgelChunk& out);

// fn(chunk, first, n) for each chunk of the line's edgels (xns: its undistorted edgels), in
// order: the chunk holds the values of edgels [first, first + n) as line_edgel_values gives them.
template <class Fn>
void for_each_edgel_chunk(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                          const Tukey* k, bool with_derivatives, Fn&& fn) {
  EdgelChunk chunk;
  const int total = static_cast<int>(obs.edgels_px.size());
  for (int first = 0; first < total; first += kEdgelChunk) {
    const int n = std::min(kEdgelChunk, total - first);
    line_edgel_values(obs, img, xns + first, n, focal, k, with_derivatives, chunk);
    fn(static_cast<const EdgelChunk&>(chunk), first, n);
  }
}

// fn(r) for each of the line's edgels, in order.
template <class Fn>
void line_residuals(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal, Fn&& fn) {
  for_each_edgel_chunk(obs, img, xns, focal, nullptr, false, [&](const EdgelChunk& c, int, int n) {
    for (int q = 0; q < n; ++q) fn(c.r[q]);
  });
}

// Tukey's cost summed over the line's edgels onto sum, in edgel order.
void add_line_cost(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                   const Tukey& k, double& sum);

// The line's block of the normal equations, formed once per line rather than once per edgel.
void add_line_block(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                    const Tukey& k, NormalEquations& ne, double shared_sigma_px);

// ---- Junctions: fn(r, J) for the two rows (x, then y); J is left unset without want_jacobian.
template <class Fn>
void junction_rows(const PointObservation& obs, const Eigen::Isometry3d& cam_T_obj, const Camera& camera,
                   bool want_jacobian, Fn&& fn) {
  const Eigen::Vector3d X = cam_T_obj * obs.p_obj;
  const Eigen::Vector2d xn(X.x() / X.z(), X.y() / X.z());
  const Eigen::Vector2d r = (camera.normalized_to_pixel(xn) - obs.px) / obs.sigma_px;
  Eigen::Matrix<double, 2, 6> J2;
  if (want_jacobian) {
    Eigen::Matrix<double, 2, 3> dn;
    dn << 1 / X.z(), 0, -X.x() / (X.z() * X.z()), 0, 1 / X.z(), -X.y() / (X.z() * X.z());
    J2 = camera.normalized_to_pixel_jacobian(xn) * dn * geometry::left_point_jacobian(X) / obs.sigma_px;
  }
  fn(r.x(), RowJ(J2.row(0)));
  fn(r.y(), RowJ(J2.row(1)));
}

// ---- Ellipse points.

// The conic of a circle's image in normalised coordinates (inside negative).
Eigen::Matrix3d circle_conic_normalized(const ModelCircle& circle, const Eigen::Isometry3d& cam_T_obj);

// First-order geometric distance of x from the conic C (normalised coordinates).
inline double conic_distance(const Eigen::Matrix3d& C, const Eigen::Vector2d& x) {
  const Eigen::Vector3d h(x.x(), x.y(), 1);
  const Eigen::Vector3d g = C * h;
  const double grad = 2 * std::hypot(g.x(), g.y());
  return grad > 0 ? h.dot(g) / grad : 0.0;
}

// fn(r, J) for each ellipse point (xns: undistorted). The Jacobian is numeric: six perturbed
// conics per ellipse, shared by all its points.
template <class Fn>
void ellipse_rows(const EllipseObservation& obs, const Eigen::Vector2d* xns, const Eigen::Isometry3d& cam_T_obj,
                  double focal, bool want_jacobian, Fn&& fn) {
  const Eigen::Matrix3d C = circle_conic_normalized(obs.circle, cam_T_obj);
  Eigen::Matrix3d Cd[6];
  constexpr double h = 1e-6;
  if (want_jacobian) {
    for (int k = 0; k < 6; ++k) {
      Vector6d xi = Vector6d::Zero();
      xi[k] = h;
      Cd[k] = circle_conic_normalized(obs.circle, geometry::apply_left(xi, cam_T_obj));
    }
  }
  for (std::size_t k = 0; k < obs.points_px.size(); ++k) {
    const Eigen::Vector2d& xn = xns[k];
    const double r = focal * conic_distance(C, xn) / obs.sigma_px;
    RowJ J;
    if (want_jacobian)
      for (int k = 0; k < 6; ++k) J[k] = (focal * conic_distance(Cd[k], xn) / obs.sigma_px - r) / h;
    fn(r, J);
  }
}

// ---- 3D points: fn(r, J) for the three rows (x, y, z).
template <class Fn>
void point_3d_rows(const Point3dObservation& obs, const Eigen::Isometry3d& cam_T_obj, bool want_jacobian, Fn&& fn) {
  const Eigen::Vector3d X = cam_T_obj * obs.p_obj;
  const Eigen::Vector3d r = (X - obs.p_cam) / obs.sigma_m;
  Eigen::Matrix<double, 3, 6> J3;
  if (want_jacobian) J3 = geometry::left_point_jacobian(X) / obs.sigma_m;
  for (int i = 0; i < 3; ++i) fn(r[i], RowJ(J3.row(i)));
}

// ---- All features of a problem, in slot order: lines, junctions, ellipses, 3D points.

enum class Rejected { Skip, Include };

class PoseTerms {
 public:
  // normalized: the undistorted edgels of every line, then the points of every ellipse, each
  // list starting at offsets[i] (lines first); rejected: one flag per slot.
  PoseTerms(const PoseProblem& problem, const Camera& camera, double focal, const std::vector<Eigen::Vector2d>& normalized,
            const std::vector<std::size_t>& offsets, const std::vector<unsigned char>& rejected)
      : problem_(problem), camera_(camera), focal_(focal), normalized_(normalized), offsets_(offsets), rejected_(rejected) {}

  // fn(r, slot) for every residual, in slot order.
  template <class Fn>
  void residuals(const Eigen::Isometry3d& cam_T_obj, Rejected which, Fn&& fn) const {
    int slot = 0;
    for (std::size_t i = 0; i < problem_.lines.size(); ++i, ++slot) {
      const LineObservation& obs = problem_.lines[i];
      if (obs.edgels_px.size() < 2 || skip(slot, which)) continue;
      line_residuals(obs, line_image(obs, cam_T_obj), line_edgels(i), focal_, [&](double r) { fn(r, slot); });
    }
    rows(cam_T_obj, which, false, [&](double r, const RowJ&, int s) { fn(r, s); });
  }

  // Tukey's cost at cam_T_obj summed over every residual in slot order (residuals() with
  // k.rho summed, the lines' edgels element-wise first); rejected features left out.
  double cost(const Eigen::Isometry3d& cam_T_obj, const Tukey& k) const;

  // The normal equations at cam_T_obj under kernel k, from scratch; rejected features left out.
  // With shared errors (shared_sigma_px >= 0: PoseOptions::line_shared_sigma_px) also
  // NormalEquations::shared, for the covariance.
  void normal_equations(const Eigen::Isometry3d& cam_T_obj, const Tukey& k, NormalEquations& ne,
                        double shared_sigma_px = -1) const;

  // The observed segments and junctions are in front of the camera. Only lines with edgels count:
  // a caller may keep empty slots for every model edge, and an unseen edge may well run behind
  // the camera (a room's wall edge), which would otherwise refuse every step.
  bool all_in_front(const Eigen::Isometry3d& cam_T_obj) const;

 private:
  bool skip(int slot, Rejected which) const { return which == Rejected::Skip && rejected_[slot]; }
  const Eigen::Vector2d* line_edgels(std::size_t line) const { return normalized_.data() + offsets_[line]; }

  // fn(r, J, slot) for every row of the features other than lines (J unset without want_jacobian).
  template <class Fn>
  void rows(const Eigen::Isometry3d& cam_T_obj, Rejected which, bool want_jacobian, Fn&& fn) const {
    int slot = static_cast<int>(problem_.lines.size());
    std::size_t list = problem_.lines.size();  // index into offsets_: lines, then ellipses
    for (const auto& obs : problem_.points) {
      if (!skip(slot, which)) junction_rows(obs, cam_T_obj, camera_, want_jacobian, [&](double r, const RowJ& J) { fn(r, J, slot); });
      ++slot;
    }
    for (const auto& obs : problem_.ellipses) {
      const Eigen::Vector2d* xns = normalized_.data() + offsets_[list++];
      if (obs.points_px.size() >= 5 && !skip(slot, which))
        ellipse_rows(obs, xns, cam_T_obj, focal_, want_jacobian, [&](double r, const RowJ& J) { fn(r, J, slot); });
      ++slot;
    }
    for (const auto& obs : problem_.points_3d) {
      if (!skip(slot, which)) point_3d_rows(obs, cam_T_obj, want_jacobian, [&](double r, const RowJ& J) { fn(r, J, slot); });
      ++slot;
    }
  }

  const PoseProblem& problem_;
  const Camera& camera_;
  double focal_;
  const std::vector<Eigen::Vector2d>& normalized_;
  const std::vector<std::size_t>& offsets_;
  const std::vector<unsigned char>& rejected_;
};

}  // namespace epichead::vision::detail
