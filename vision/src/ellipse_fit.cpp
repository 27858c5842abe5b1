#include "epichead/vision/ellipse_fit.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "ransac_common.h"

namespace epichead::vision {
namespace {

// Centre and scale that bring points to mean 0 and RMS distance sqrt(2): conics of pixel
// coordinates in the hundreds have terms 1e5 apart, which the 3x3 and 5x5 solves cannot afford.
struct Normalisation { double ox = 0, oy = 0, scale = 1; };

Normalisation normalisation(const double* x, const double* y, const int* idx, int n) {
  Normalisation t;
  for (int k = 0; k < n; ++k) {
    const int i = idx ? idx[k] : k;
    t.ox += x[i];
    t.oy += y[i];
  }
  t.ox /= n;
  t.oy /= n;
  double sq = 0;
  for (int k = 0; k < n; ++k) {
    const int i = idx ? idx[k] : k;
    sq += (x[i] - t.ox) * (x[i] - t.ox) + (y[i] - t.oy) * (y[i] - t.oy);
  }
  const double rms = std::sqrt(sq / n);
  t.scale = rms > 1e-12 ? std::sqrt(2.0) / rms : 1.0;
  return t;
}

// Conic of normalised coordinates -> conic of pixels: M_px = T^T M_n T, T = the normalisation.
std::optional<Ellipse> denormalise(const Conic& k, const Normalisation& t) {
  Eigen::Matrix3d m;
  m << k[0], 0.5 * k[1], 0.5 * k[3], 0.5 * k[1], k[2], 0.5 * k[4], 0.5 * k[3], 0.5 * k[4], k[5];
  Eigen::Matrix3d T;
  T << t.scale, 0, -t.scale * t.ox, 0, t.scale, -t.scale * t.oy, 0, 0, 1;
  return Ellipse::from_conic_matrix(T.transpose() * m * T);
}

}  // namespace

std::optional<Ellipse> fit_ellipse_direct(const double* x, const double* y, const int* idx, int n) {
  if (n < 5) return std::nullopt;
  const Normalisation t = normalisation(x, y, idx, n);
  // Halir and Flusser's split of the 6x6 scatter matrix into quadratic (D1) and linear (D2)
  // parts: the constraint only involves the quadratic part, which leaves a 3x3 eigenproblem.
  Eigen::Matrix3d S1 = Eigen::Matrix3d::Zero(), S2 = Eigen::Matrix3d::Zero(), S3 = Eigen::Matrix3d::Zero();
  for (int k = 0; k < n; ++k) {
    const int i = idx ? idx[k] : k;
    const double u = (x[i] - t.ox) * t.scale, v = (y[i] - t.oy) * t.scale;
    const Eigen::Vector3d d1(u * u, u * v, v * v), d2(u, v, 1.0);
    S1.noalias() += d1 * d1.transpose();
    S2.noalias() += d1 * d2.transpose();
    S3.noalias() += d2 * d2.transpose();
  }
  Eigen::FullPivLU<Eigen::Matrix3d> s3(S3);
  if (!s3.isInvertible() || std::fabs(S3.determinant()) < 1e-12 * std::pow(S3.norm(), 3)) return std::nullopt;
  const Eigen::Matrix3d T = -s3.solve(S2.transpose());
  const Eigen::Matrix3d M = S1 + S2 * T;
  // Premultiply by the inverse of the constraint matrix C1 = [0 0 2; 0 -1 0; 2 0 0].
  Eigen::Matrix3d R;
  R.row(0) = 0.5 * M.row(2);
  R.row(1) = -M.row(1);
  R.row(2) = 0.5 * M.row(0);
  Eigen::EigenSolver<Eigen::Matrix3d> es(R);
  if (es.info() != Eigen::Success) return std::nullopt;
  // The solution is the eigenvector with 4AC - B^2 > 0 (exactly one in exact arithmetic; with
  // noise take the smallest such eigenvalue, the least algebraic error).
  int pick = -1;
  double best_lambda = 0;
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d v = es.eigenvectors().col(j).real();
    const double cond = 4 * v[0] * v[2] - v[1] * v[1];
    const double lambda = es.eigenvalues()[j].real();
    if (cond > 0 && std::fabs(es.eigenvalues()[j].imag()) < 1e-9 * (1 + std::fabs(lambda)) &&
        (pick < 0 || std::fabs(lambda) < best_lambda)) {
      pick = j;
      best_lambda = std::fabs(lambda);
    }
  }
  if (pick < 0) return std::nullopt;
  const Eigen::Vector3d a1 = es.eigenvectors().col(pick).real();
  const Eigen::Vector3d a2 = T * a1;
  Conic k;
  k << a1, a2;
  return denormalise(k, t);
}

std::optional<Conic> conic_through_5(const double* x, const double* y, const int* idx, double ox, double oy,
                                     double scale) {
  // F = 1: the origin (the centroid of the points, inside any ellipse through most of them)
  // is not on the conic, so its F is not 0.
  Eigen::Matrix<double, 5, 5> A;
  Eigen::Matrix<double, 5, 1> b = Eigen::Matrix<double, 5, 1>::Constant(-1.0);
  for (int k = 0; k < 5; ++k) {
    const double u = (x[idx[k]] - ox) * scale, v = (y[idx[k]] - oy) * scale;
    A.row(k) << u * u, u * v, v * v, u, v;
  }
  Eigen::PartialPivLU<Eigen::Matrix<double, 5, 5>> lu(A);
  if (!(std::fabs(lu.determinant()) > 1e-10)) return std::nullopt;  // repeated or collinear points
  Conic k;
  k << lu.solve(b), 1.0;
  if (!k.allFinite()) return std::nullopt;
  return k;
}

EllipseRansac::EllipseRansac(const EllipseRansacOptions& options, int max_points)
    : options_(options), max_points_(std::max(max_points, 5)) {
  xn_.resize(max_points_);
  yn_.resize(max_points_);
  hypotheses_.reserve(16);
  candidates_.reserve(16);
  inliers_.reserve(static_cast<std::size_t>(max_points_) * 16);
  scratch_.reserve(max_points_);
  claimed_.assign(max_points_, 0);
}

int EllipseRansac::count_support(const Conic& k) const {
  // |Q| <= d |grad Q|, squared: no root or division per point.
  const double tol = options_.inlier_distance_px * scale_;
  const double tol2 = tol * tol;
  int support = 0;
  for (int i = 0; i < n_; ++i) {
    const double u = xn_[i], v = yn_[i];
    const double q = k[0] * u * u + k[1] * u * v + k[2] * v * v + k[3] * u + k[4] * v + k[5];
    const double gx = 2 * k[0] * u + k[1] * v + k[3], gy = k[1] * u + 2 * k[2] * v + k[4];
    support += q * q <= tol2 * (gx * gx + gy * gy);
  }
  return support;
}

bool EllipseRansac::plausible(const Ellipse& e) const {
  return e.valid() && e.semi_minor_px >= options_.min_semi_minor_px && e.semi_major_px <= options_.max_semi_major_px &&
         e.semi_major_px >= options_.min_semi_major_px && e.semi_minor_px <= options_.max_semi_minor_px;
}

bool EllipseRansac::same_ellipse(const Ellipse& a, const Ellipse& b) const {
  const double sep = options_.min_separation_px;
  return (a.centre_px - b.centre_px).norm() < sep && std::fabs(a.semi_major_px - b.semi_major_px) < sep &&
         std::fabs(a.semi_minor_px - b.semi_minor_px) < sep;
}

void EllipseRansac::collect_inliers(const Ellipse& e) {
  scratch_.clear();
  // In normalised coordinates, like the support count (the pixel conic's terms are badly scaled).
  Ellipse en = e;
  en.centre_px = (e.centre_px - Eigen::Vector2d(ox_, oy_)) * scale_;
  en.semi_major_px *= scale_;
  en.semi_minor_px *= scale_;
  const Conic k = en.conic();
  const double tol = options_.inlier_distance_px * scale_, tol2 = tol * tol;
  for (int i = 0; i < n_; ++i) {
    const double u = xn_[i], v = yn_[i];
    const double q = conic_value(k, u, v);
    const double gx = 2 * k[0] * u + k[1] * v + k[3], gy = k[1] * u + 2 * k[2] * v + k[4];
    if (q * q <= tol2 * (gx * gx + gy * gy)) scratch_.push_back(i);
  }
}

int EllipseRansac::fit(const double* x, const double* y, const int* group, int n) {
  candidates_.clear();
  inliers_.clear();
  hypotheses_.clear();
  iterations_ = 0;
  n_ = std::min(n, max_points_);
  x_ = x;
  y_ = y;
  const int max_keep = std::max(1, options_.max_candidates);
  const int min_support = std::max(5, options_.min_support);
  if (n_ < min_support) return 0;
  const Normalisation t = normalisation(x, y, nullptr, n_);
  ox_ = t.ox;
  oy_ = t.oy;
  scale_ = t.scale;
  for (int i = 0; i < n_; ++i) {
    xn_[i] = (x[i] - ox_) * scale_;
    yn_[i] = (y[i] - oy_) * scale_;
  }
  ransac::Xorshift32 rng(options_.seed);  // a local: its state stays in a register
  const double log_fail = ransac::log_failure(options_.probability);
  const double keep = std::clamp(options_.keep_ratio, 0.0, 1.0);
  // Eq. 4 for 5-point samples; with several candidates wanted, w = keep * inlier ratio so that
  // a candidate at keep * best is also sampled with probability p.
  const double w_factor = max_keep > 1 ? keep : 1.0;
  auto same = [this](const Hypothesis& a, const Hypothesis& b) { return same_ellipse(a.ellipse, b.ellipse); };
  int best = 0;
  int budget = options_.max_iterations;
  int sample[5];
  for (; iterations_ < budget; ++iterations_) {
    // Five points from five different groups (a few redraws; give up on this sample otherwise).
    int got = 0;
    for (int tries = 0; got < 5 && tries < 40; ++tries) {
      const int i = rng.below(n_);
      bool clash = false;
      for (int j = 0; j < got; ++j) clash = clash || sample[j] == i || (group && group[sample[j]] == group[i]);
      if (!clash) sample[got++] = i;
    }
    if (got < 5) continue;
    const auto k = conic_through_5(xn_.data(), yn_.data(), sample, 0.0, 0.0, 1.0);
    if (!k || 4 * (*k)[0] * (*k)[2] - (*k)[1] * (*k)[1] <= 0) continue;  // not an ellipse
    const int support = count_support(*k);
    if (support < min_support || support < keep * best) continue;
    auto e = denormalise(*k, t);
    if (!e || !plausible(*e)) continue;
    if (support > best) {
      best = support;
      const double w = w_factor * static_cast<double>(best) / n_;
      budget = std::max(1, ransac::iterations_needed(log_fail, w, 5, options_.max_iterations));
    }
    ransac::pool_hypothesis(hypotheses_, Hypothesis{*e, *k, support}, same);
  }
  // Refine: inliers -> direct fit -> inliers -> direct fit -> final inliers.
  ransac::sort_strongest_first(hypotheses_);
  std::fill(claimed_.begin(), claimed_.begin() + n_, 0);
  for (const Hypothesis& h : hypotheses_) {
    // Strongest first: once max_candidates are accepted the rest would be cut below anyway,
    // and a hypothesis on an accepted ellipse needs no refinement (the 3x3 eigenproblems of
    // the refinement cost more than the whole sampling loop).
    if (static_cast<int>(candidates_.size()) >= max_keep) break;
    if (h.support < keep * best) continue;
    bool known = false;
    for (const EllipseFit& f : candidates_) known = known || same_ellipse(f.ellipse, h.ellipse);
    if (known) continue;
    Ellipse e = h.ellipse;
    for (int pass = 0; pass < 2; ++pass) {
      collect_inliers(e);
      if (static_cast<int>(scratch_.size()) < 5) break;
      const auto refined = fit_ellipse_direct(x_, y_, scratch_.data(), static_cast<int>(scratch_.size()));
      if (!refined || !plausible(*refined)) break;
      e = *refined;
    }
    collect_inliers(e);
    const int support = static_cast<int>(scratch_.size());
    if (support < min_support) continue;
    bool duplicate = false;
    for (const EllipseFit& f : candidates_) duplicate = duplicate || same_ellipse(f.ellipse, e);
    if (duplicate) continue;
    // A weaker ellipse must stand on points of its own, not on the inliers of stronger ones.
    if (!ransac::claim_own_points(scratch_.data(), support, claimed_, std::max<double>(keep * best, min_support)))
      continue;
    EllipseFit fit;
    fit.ellipse = e;
    fit.support = support;
    fit.inlier_begin = static_cast<int>(inliers_.size());
    inliers_.insert(inliers_.end(), scratch_.begin(), scratch_.end());
    candidates_.push_back(fit);
  }
  ransac::sort_and_cut(candidates_, max_keep, keep);
  return static_cast<int>(candidates_.size());
}

}  // namespace epichead::vision
