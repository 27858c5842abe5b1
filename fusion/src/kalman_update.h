#pragma once
// The gated Kalman update shared by the IMU filter and the constant-velocity filter: both observe
// the 6-dof pose through a linear map H of their error state; the IMU filter's unaided updates
// observe its tilt and position the same way.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <limits>

#include "epichead/fusion/nav_state.h"
#include "epichead/geometry/se3.h"

namespace epichead::fusion::detail {

using geometry::Matrix6d;
using geometry::Vector6d;

// Computes the correction dx for an M-dimensional innovation r with measurement covariance Rm;
// updates P (Joseph form, symmetrised). Returns r' S^-1 r; when it exceeds gate_chi2, P and dx are
// left untouched and `applied` is false. The vision update observes the 6-dof pose (M = 6); the
// unaided updates (unaided_update.h) the down (M = 2) and the position (M = 3).
template <int N, int M>
double kalman_update(Eigen::Matrix<double, N, N>& P, const Eigen::Matrix<double, M, N>& H, const Eigen::Matrix<double, M, 1>& r,
                     const Eigen::Matrix<double, M, M>& Rm, double gate_chi2, Eigen::Matrix<double, N, 1>& dx, bool& applied) {
  const Eigen::Matrix<double, N, M> PHt = P * H.transpose();
  const Eigen::Matrix<double, M, M> S = H * PHt + Rm;
  const Eigen::LLT<Eigen::Matrix<double, M, M>> llt(S);
  applied = false;
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  const double d2 = r.dot(llt.solve(r));
  if (!(d2 <= gate_chi2)) return d2;
  // K = P H' S^-1, computed as (S^-1 H P)' since S is symmetric.
  const Eigen::Matrix<double, N, M> K = llt.solve(PHt.transpose()).transpose();
  dx = K * r;
  Eigen::Matrix<double, N, N> IKH = -K * H;
  IKH.diagonal().array() += 1.0;
  P = IKH * P * IKH.transpose() + K * Rm * K.transpose();
  P = 0.5 * (P + P.transpose()).eval();
  applied = true;
  return d2;
}

// kalman_update on the filter's error state (nav_state.h). While the vision error is not carried
// its rows and columns of P are zero, and the update is done on the navigation block alone: the
// same arithmetic as a 17-dimensional filter (bit for bit: longer sums of zeros round
// differently), and a third less of it.
template <int M>
double update_error_state(ErrorCovariance& P, const Eigen::Matrix<double, M, err::dim>& H, const Eigen::Matrix<double, M, 1>& r,
                          const Eigen::Matrix<double, M, M>& Rm, double gate_chi2, ErrorVector& dx, bool& applied) {
  constexpr int n = err::nav, v = err::dim - err::nav;
  if (!P.bottomRows<v>().isZero(0)) return kalman_update<err::dim, M>(P, H, r, Rm, gate_chi2, dx, applied);
  Eigen::Matrix<double, n, n> Pn = P.topLeftCorner<n, n>();
  const Eigen::Matrix<double, M, n> Hn = H.template leftCols<n>();
  Eigen::Matrix<double, n, 1> dxn;
  const double d2 = kalman_update<n, M>(Pn, Hn, r, Rm, gate_chi2, dxn, applied);
  if (!applied) return d2;
  P.topLeftCorner<n, n>() = Pn;
  dx.setZero();
  dx.head<n>() = dxn;
  return d2;
}

}  // namespace epichead::fusion::detail
