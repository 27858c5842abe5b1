#include "epichead/vision/ellipse.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace epichead::vision {

double wrap_angle(double a) {
  a = std::remainder(a, 2 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2 * std::numbers::pi : a;
}

bool Ellipse::valid() const {
  return centre_px.allFinite() && std::isfinite(angle_rad) && std::isfinite(semi_major_px) && semi_minor_px > 0 &&
         semi_major_px >= semi_minor_px;
}

std::optional<Ellipse> Ellipse::from_conic(const Conic& k) {
  if (!k.allFinite()) return std::nullopt;
  const double A = k[0], B = k[1], C = k[2], D = k[3], E = k[4], F = k[5];
  const double det = 4 * A * C - B * B;  // > 0 for an ellipse
  const double scale = std::max({std::fabs(A), std::fabs(B), std::fabs(C)});
  if (!(scale > 0) || det <= 1e-12 * scale * scale) return std::nullopt;
  Ellipse e;
  e.centre_px = Eigen::Vector2d((B * E - 2 * C * D) / det, (B * D - 2 * A * E) / det);
  // Q at the centre: Q(c + d) = d^T M d + Q(c) with M = [A B/2; B/2 C].
  const double f0 = F + 0.5 * (D * e.centre_px.x() + E * e.centre_px.y());
  // Eigenvalues of M in closed form (2x2 symmetric): both share a sign for an ellipse.
  const double mean = 0.5 * (A + C), half_diff = 0.5 * (A - C);
  const double root = std::hypot(half_diff, 0.5 * B);
  const double l_small = mean - root, l_large = mean + root;  // |.| ordering depends on the sign
  const double l_major = mean > 0 ? l_small : l_large;  // the smaller |lambda| gives the longer axis
  const double l_minor = mean > 0 ? l_large : l_small;
  if (l_major * l_minor <= 0 || -f0 / l_major <= 0) return std::nullopt;  // imaginary or degenerate
  e.semi_major_px = std::sqrt(-f0 / l_major);
  e.semi_minor_px = std::sqrt(-f0 / l_minor);
  // Eigenvector of l_major: (B/2, l - A) or (l - C, B/2), whichever is better conditioned.
  Eigen::Vector2d u(0.5 * B, l_major - A);
  const Eigen::Vector2d u2(l_major - C, 0.5 * B);
  if (u2.squaredNorm() > u.squaredNorm()) u = u2;
  e.angle_rad = u.squaredNorm() > 0 ? std::atan2(u.y(), u.x()) : 0.0;
  if (!e.valid()) return std::nullopt;
  return e;
}

std::optional<Ellipse> Ellipse::from_conic_matrix(const Eigen::Matrix3d& m) {
  Conic k;
  k << m(0, 0), m(0, 1) + m(1, 0), m(1, 1), m(0, 2) + m(2, 0), m(1, 2) + m(2, 1), m(2, 2);
  return from_conic(k);
}

Eigen::Vector2d Ellipse::major_axis() const { return {std::cos(angle_rad), std::sin(angle_rad)}; }
Eigen::Vector2d Ellipse::minor_axis() const { return {-std::sin(angle_rad), std::cos(angle_rad)}; }

Conic Ellipse::conic() const {
  // (d.u)^2 / a^2 + (d.v)^2 / b^2 - 1 with d = p - centre, expanded.
  const Eigen::Vector2d u = major_axis(), v = minor_axis();
  const double ia = 1.0 / (semi_major_px * semi_major_px), ib = 1.0 / (semi_minor_px * semi_minor_px);
  Eigen::Matrix2d M = ia * u * u.transpose() + ib * v * v.transpose();
  const Eigen::Vector2d g = -2.0 * M * centre_px;
  const double f = centre_px.dot(M * centre_px) - 1.0;
  Conic k;
  k << M(0, 0), 2 * M(0, 1), M(1, 1), g.x(), g.y(), f;
  return k / k.norm();
}

Eigen::Matrix3d Ellipse::conic_matrix() const {
  const Conic k = conic();
  Eigen::Matrix3d m;
  m << k[0], 0.5 * k[1], 0.5 * k[3], 0.5 * k[1], k[2], 0.5 * k[4], 0.5 * k[3], 0.5 * k[4], k[5];
  return m;
}

Eigen::Vector2d Ellipse::point(double t) const {
  return centre_px + semi_major_px * std::cos(t) * major_axis() + semi_minor_px * std::sin(t) * minor_axis();
}

Eigen::Vector2d Ellipse::tangent(double t) const {
  return -semi_major_px * std::sin(t) * major_axis() + semi_minor_px * std::cos(t) * minor_axis();
}

Eigen::Vector2d Ellipse::outward_normal(double t) const {
  // Gradient of (x/a)^2 + (y/b)^2 in the ellipse frame: (cos t / a, sin t / b).
  const Eigen::Vector2d n = std::cos(t) / semi_major_px * major_axis() + std::sin(t) / semi_minor_px * minor_axis();
  return n.normalized();
}

double Ellipse::param_of_polar(double polar_rad) const {
  const Eigen::Vector2d d(std::cos(polar_rad), std::sin(polar_rad));
  return std::atan2(semi_major_px * d.dot(minor_axis()), semi_minor_px * d.dot(major_axis()));
}

double Ellipse::polar_of_param(double t) const {
  const Eigen::Vector2d d = point(t) - centre_px;
  return std::atan2(d.y(), d.x());
}

std::optional<EllipseArc> EllipseArc::overlap(const EllipseArc& a, const EllipseArc& b) {
  if (a.full()) return b;
  if (b.full()) return a;
  constexpr double two_pi = 6.283185307179586;
  // b's begin measured from a's, in [0, 2 pi): b covers [d, d + span] and, wrapped once,
  // [d - 2 pi, d - 2 pi + span] of a's [0, span].
  const double d = std::fmod(std::fmod(b.begin_rad - a.begin_rad, two_pi) + two_pi, two_pi);
  double best_lo = 0, best_len = 0;
  for (const double start : {d, d - two_pi}) {
    const double lo = std::max(0.0, start), hi = std::min(a.span_rad, start + b.span_rad);
    if (hi - lo > best_len) { best_lo = lo; best_len = hi - lo; }
  }
  if (!(best_len > 0)) return std::nullopt;
  return EllipseArc{a.begin_rad + best_lo, best_len};
}

double Ellipse::distance(const Eigen::Vector2d& p) const {
  const Conic k = conic();
  const double q = conic_value(k, p.x(), p.y());
  const double gx = 2 * k[0] * p.x() + k[1] * p.y() + k[3], gy = k[1] * p.x() + 2 * k[2] * p.y() + k[4];
  const double g = std::hypot(gx, gy);
  return g > 0 ? std::fabs(q) / g : std::numeric_limits<double>::infinity();
}

}  // namespace epichead::vision
