#pragma once
// The gated Kalman update shared by the IMU filter and the constant-velocity filter: both observe
// the 6-dof pose through a linear map H of their error state; the IMU filter's unaided updates
// observe its tilt and position the same way.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <limits>

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

}  // namespace epichead::fusion::detail
