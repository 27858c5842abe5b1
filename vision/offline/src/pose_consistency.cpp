#include "epichead/vision/offline/pose_consistency.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include "epichead/common/chi2_bounds.h"

namespace epichead::vision {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// e' C^-1 e over the whole twist, or with an axis turn u over the subspace orthogonal to u: the
// marginal of the five directions the scoring sees, whatever turn about the axis it removed.
double nees(const FrameScore& s, const Eigen::Matrix<double, 6, 6>& C) {
  if (s.axis_twist.isZero()) {
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> ldlt(C);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return kNaN;
    return s.error_twist.dot(ldlt.solve(s.error_twist));
  }
  // The columns of Q after the first span the complement of u.
  const Eigen::HouseholderQR<Eigen::Matrix<double, 6, 1>> qr(s.axis_twist);
  const Eigen::Matrix<double, 6, 6> Q = qr.householderQ();
  const Eigen::Matrix<double, 6, 5> P = Q.rightCols<5>();
  const Eigen::Matrix<double, 5, 1> z = P.transpose() * s.error_twist;
  const Eigen::LDLT<Eigen::Matrix<double, 5, 5>> ldlt(P.transpose() * C * P);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0)) return kNaN;
  return z.dot(ldlt.solve(z));
}

}  // namespace

PoseConsistency pose_consistency(const ScoreSummary& summary, const std::vector<StampedCovariance>& covariances) {
  bool with_axis = false;
  for (const FrameScore& s : summary.per_frame) with_axis = with_axis || !s.axis_twist.isZero();
  const int dof = with_axis ? 5 : 6;
  const common::Chi2Bounds b = common::chi2_95_bounds(dof);
  std::unordered_map<int, const StampedCovariance*> by_frame;
  for (const auto& c : covariances) by_frame.emplace(c.frame, &c);
  PoseConsistency out;
  std::vector<double> nees_values;
  for (const FrameScore& s : summary.per_frame) {
    if (!s.success || !s.error_twist.allFinite()) continue;
    const auto it = by_frame.find(s.frame);
    if (it == by_frame.end()) continue;
    const double v = nees(s, it->second->covariance);
    if (!std::isfinite(v)) continue;
    nees_values.push_back(v);
    out.per_frame.push_back({s.frame, v});
  }
  out.dof = dof;
  out.count = static_cast<int>(nees_values.size());
  if (nees_values.empty()) {
    out.mean = out.median = out.scale_for_mean = kNaN;
    return out;
  }
  double sum = 0;
  int below = 0, above = 0;
  for (double v : nees_values) {
    sum += v;
    below += v < b.low;
    above += v > b.high;
  }
  const double n = static_cast<double>(nees_values.size());
  out.mean = sum / n;
  std::nth_element(nees_values.begin(), nees_values.begin() + nees_values.size() / 2, nees_values.end());
  out.median = nees_values[nees_values.size() / 2];
  out.below_2_5pct = below / n;
  out.above_97_5pct = above / n;
  out.within_95pct = 1 - out.below_2_5pct - out.above_97_5pct;
  out.scale_for_mean = out.mean / dof;
  return out;
}

}  // namespace epichead::vision
