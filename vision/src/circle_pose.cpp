#include "epichead/vision/circle_pose.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace epichead::vision {
namespace {

Ellipse from_params(const EllipseParams& q) {
  Ellipse e;
  e.centre_px = q.head<2>();
  e.semi_major_px = q[2];
  e.semi_minor_px = q[3];
  e.angle_rad = q[4];
  return e;
}

// Signed distance of p from the ellipse (Sampson), negative inside. Unlike Ellipse::valid
// this accepts b > a, which a finite-difference step can produce for a near-circle.
double signed_distance(const EllipseParams& q, const Eigen::Vector2d& p) {
  const double c = std::cos(q[4]), s = std::sin(q[4]);
  const Eigen::Vector2d d = p - q.head<2>();
  const double u = (c * d.x() + s * d.y()) / q[2], v = (-s * d.x() + c * d.y()) / q[3];
  const double value = u * u + v * v - 1.0;
  // Gradient of the value in pixels: 2 (u / a) u_axis + 2 (v / b) v_axis.
  const double g = 2.0 * std::hypot(u / q[2], v / q[3]);
  return g > 0 ? value / g : 0.0;
}

}  // namespace

EllipseParams ellipse_params(const Ellipse& e) {
  EllipseParams q;
  q << e.centre_px, e.semi_major_px, e.semi_minor_px, e.angle_rad;
  return q;
}

std::expected<std::array<CircleSolution, 2>, std::string> circle_solutions(const Ellipse& ellipse_px,
                                                                           const Camera& camera, double radius_m) {
  if (!(radius_m > 0) || !std::isfinite(radius_m)) return std::unexpected("circle radius must be > 0, got " + std::to_string(radius_m));
  if (!ellipse_px.valid()) return std::unexpected<std::string>("invalid ellipse");
  // The viewing cone X^T C X = 0 in the camera frame: the image conic pulled back through K.
  const Eigen::Matrix3d K = camera.K();
  Eigen::Matrix3d C = K.transpose() * ellipse_px.conic_matrix() * K;
  C = 0.5 * (C + C.transpose());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
  Eigen::Vector3d l = es.eigenvalues();  // ascending
  Eigen::Matrix3d V = es.eigenvectors();
  // Signature (+, +, -) after a sign change if needed: a real cone has one eigenvalue of the
  // other sign.
  if (l[1] < 0) {
    C = -C;
    l = -l;
    V = V.rowwise().reverse().eval();
    l = l.reverse().eval();
  }
  if (!(l[0] < 0 && l[1] > 0)) return std::unexpected<std::string>("the ellipse's viewing cone is degenerate");
  const double l3 = l[0], l2 = l[1], l1 = l[2];
  const Eigen::Vector3d e3 = V.col(0), e1 = V.col(2);
  // The planes that cut an elliptic cone in circles contain the axis of the middle eigenvalue;
  // their normals are (+-sqrt((l1 - l2) / (l1 - l3)), 0, sqrt((l2 - l3) / (l1 - l3))) in the
  // eigenbasis (e1, e2, e3).
  const double g1 = std::sqrt(std::max(0.0, (l1 - l2) / (l1 - l3))), g3 = std::sqrt(std::max(0.0, (l2 - l3) / (l1 - l3)));
  std::array<CircleSolution, 2> out;
  const Eigen::Matrix3d C_inv = C.inverse();
  for (int k = 0; k < 2; ++k) {
    Eigen::Vector3d n = (k == 0 ? g1 : -g1) * e1 + g3 * e3;
    n.normalize();
    // The image of the circle's centre is the pole of the plane's vanishing line (= n).
    Eigen::Vector3d xc = C_inv * n;
    if (std::fabs(xc.z()) < 1e-12) return std::unexpected<std::string>("the circle's centre projects to infinity");
    xc /= xc.z();
    // A point of the cone through xc's row: (xc + s e_x)^T C (xc + s e_x) = 0.
    const Eigen::Vector3d w = Eigen::Vector3d::UnitX();
    const double qa = w.dot(C * w), qb = 2 * w.dot(C * xc), qc = xc.dot(C * xc);
    const double disc = qb * qb - 4 * qa * qc;
    if (!(disc >= 0) || qa == 0) return std::unexpected<std::string>("the ellipse's centre ray misses the cone");
    const Eigen::Vector3d x_rim = xc + ((-qb + std::sqrt(disc)) / (2 * qa)) * w;
    // Everything scales with the plane's distance: solve at distance 1, then scale to the radius.
    const double dc = n.dot(xc), dr = n.dot(x_rim);
    if (std::fabs(dc) < 1e-12 || std::fabs(dr) < 1e-12) return std::unexpected<std::string>("the circle's plane contains the camera centre");
    const Eigen::Vector3d centre1 = xc / dc, rim1 = x_rim / dr;
    const double r1 = (rim1 - centre1).norm();
    if (!(r1 > 0)) return std::unexpected<std::string>("degenerate ellipse");
    Eigen::Vector3d centre = centre1 * (radius_m / r1);
    if (centre.z() < 0) centre = -centre;
    if (n.dot(-centre) < 0) n = -n;  // toward the camera
    out[static_cast<std::size_t>(k)] = {centre, n};
  }
  return out;
}

std::expected<CirclePose, std::string> circle_pose(const Ellipse& ellipse_px, const Camera& camera, double radius_m,
                                                   const Eigen::Vector3d& prior_normal_cam,
                                                   const EllipseCovariance* ellipse_cov) {
  if (!prior_normal_cam.allFinite() || prior_normal_cam.norm() < 1e-12)
    return std::unexpected<std::string>("prior normal must be a finite non-zero vector");
  const Eigen::Vector3d prior = prior_normal_cam.normalized();
  auto pick = [&](const std::array<CircleSolution, 2>& s, const Eigen::Vector3d& towards, CircleSolution* other) {
    const int k = std::fabs(s[0].normal_cam.dot(towards)) >= std::fabs(s[1].normal_cam.dot(towards)) ? 0 : 1;
    CircleSolution c = s[static_cast<std::size_t>(k)];
    if (c.normal_cam.dot(towards) < 0) c.normal_cam = -c.normal_cam;
    if (other) {
      *other = s[static_cast<std::size_t>(1 - k)];
      if (other->normal_cam.dot(towards) < 0) other->normal_cam = -other->normal_cam;
    }
    return c;
  };
  auto both = circle_solutions(ellipse_px, camera, radius_m);
  if (!both) return std::unexpected(both.error());
  CirclePose pose;
  pose.circle = pick(*both, prior, &pose.other);
  pose.ambiguity_rad = std::acos(std::clamp(std::fabs((*both)[0].normal_cam.dot((*both)[1].normal_cam)), 0.0, 1.0));
  if (!ellipse_cov) return pose;
  // Central differences through the closed form, each perturbed solution taken on the branch
  // of the nominal one (nearest normal).
  Eigen::Matrix<double, 6, 5> J;
  const EllipseParams q0 = ellipse_params(ellipse_px);
  for (int j = 0; j < 5; ++j) {
    const double h = j == 4 ? 1e-5 : 1e-4 * std::max(1.0, std::fabs(q0[j]));
    Eigen::Matrix<double, 6, 1> f[2];
    for (int side = 0; side < 2; ++side) {
      EllipseParams q = q0;
      q[j] += side == 0 ? h : -h;
      Ellipse e = from_params(q);
      if (e.semi_minor_px > e.semi_major_px) {  // keep a >= b: swap the axes, turn by 90 deg
        std::swap(e.semi_major_px, e.semi_minor_px);
        e.angle_rad += 1.5707963267948966;
      }
      auto s = circle_solutions(e, camera, radius_m);
      if (!s) return std::unexpected("covariance: " + s.error());
      const CircleSolution c = pick(*s, pose.circle.normal_cam, nullptr);
      f[side] << c.centre_cam, c.normal_cam;
    }
    J.col(j) = (f[0] - f[1]) / (2 * h);
  }
  pose.covariance = J * (*ellipse_cov) * J.transpose();
  return pose;
}

std::optional<EllipseCovariance> ellipse_covariance(const Ellipse& e, const Eigen::Vector2d* p, int n, double sigma_px) {
  if (n < 5 || !e.valid()) return std::nullopt;
  const EllipseParams q0 = ellipse_params(e);
  Eigen::Matrix<double, 5, 5> JtJ = Eigen::Matrix<double, 5, 5>::Zero();
  double sq = 0;
  for (int i = 0; i < n; ++i) {
    Eigen::Matrix<double, 5, 1> g;
    for (int j = 0; j < 5; ++j) {
      const double h = j == 4 ? 1e-6 : 1e-5 * std::max(1.0, std::fabs(q0[j]));
      EllipseParams qp = q0, qm = q0;
      qp[j] += h;
      qm[j] -= h;
      g[j] = (signed_distance(qp, p[i]) - signed_distance(qm, p[i])) / (2 * h);
    }
    JtJ.noalias() += g * g.transpose();
    const double r = signed_distance(q0, p[i]);
    sq += r * r;
  }
  const double sigma = std::max(sigma_px, std::sqrt(sq / n));
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 5, 5>> es(JtJ);
  const double top = es.eigenvalues().maxCoeff();
  if (!(top > 0)) return std::nullopt;
  EllipseCovariance cov = EllipseCovariance::Zero();
  for (int j = 0; j < 5; ++j) {
    const double l = es.eigenvalues()[j];
    if (l > 1e-9 * top) cov.noalias() += (1.0 / l) * es.eigenvectors().col(j) * es.eigenvectors().col(j).transpose();
  }
  return cov * sigma * sigma;
}

}  // namespace epichead::vision
