#pragma once
// An ellipse in the image (the projection of a model circle, or a fit to edgels): centre, semi
// axes and orientation, with conversions to and from the implicit conic
// A x^2 + B x y + C y^2 + D x + E y + F = 0, points and normals by the parametric angle t
// (p(t) = centre + a cos t u + b sin t v, u the major axis, v = u turned by +90 deg), and the
// approximate (Sampson) distance of a point. Angles grow from +x toward +y (image y down).
#include <optional>

#include <Eigen/Core>

namespace epichead::vision {

// Conic coefficients (A, B, C, D, E, F) of A x^2 + B x y + C y^2 + D x + E y + F = 0.
using Conic = Eigen::Matrix<double, 6, 1>;

struct Ellipse {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  double semi_major_px = 0, semi_minor_px = 0;  // a >= b > 0 for a valid ellipse
  double angle_rad = 0;                         // of the major axis from the image x axis

  bool valid() const;
  // The real ellipse of a conic, or nullopt (hyperbola, parabola, imaginary or degenerate).
  static std::optional<Ellipse> from_conic(const Conic& k);
  // The same from the symmetric 3x3 form p^T M p = 0, p = (x, y, 1).
  static std::optional<Ellipse> from_conic_matrix(const Eigen::Matrix3d& m);
  // Conic coefficients scaled to unit norm, with F <= 0 (negative inside the ellipse).
  Conic conic() const;
  Eigen::Matrix3d conic_matrix() const;

  Eigen::Vector2d major_axis() const;  // unit u
  Eigen::Vector2d minor_axis() const;  // unit v = u turned by +90 deg
  Eigen::Vector2d point(double t_rad) const;
  Eigen::Vector2d tangent(double t_rad) const;  // dp/dt (not unit)
  Eigen::Vector2d outward_normal(double t_rad) const;  // unit
  // Parametric angle of the contour point seen from the centre in direction polar_rad, and back.
  double param_of_polar(double polar_rad) const;
  double polar_of_param(double t_rad) const;
  // First-order (Sampson) distance of p from the contour, px: |Q(p)| / |grad Q(p)|.
  double distance(const Eigen::Vector2d& p_px) const;
};

// An arc of an ellipse's contour: polar angles begin_rad .. begin_rad + span_rad about the
// centre, in the direction of growing angle. span_rad >= 2 pi is the whole ellipse.
struct EllipseArc {
  double begin_rad = 0;
  double span_rad = 6.283185307179586;
  bool full() const { return span_rad >= 6.283185307179586 - 1e-9; }
  // The longest piece both arcs cover (angles taken about the same centre); nullopt when they
  // do not overlap.
  static std::optional<EllipseArc> overlap(const EllipseArc& a, const EllipseArc& b);
};

// Signed evaluation Q(p) of conic coefficients and its gradient, for fits and support counts.
inline double conic_value(const Conic& k, double x, double y) {
  return k[0] * x * x + k[1] * x * y + k[2] * y * y + k[3] * x + k[4] * y + k[5];
}

// Wraps an angle into (-pi, pi].
double wrap_angle(double angle_rad);

}  // namespace epichead::vision
