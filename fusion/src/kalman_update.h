#pragma once
// The gated Kalman update shared by the IMU filter and the constant-velocity filter: both observe
// the 6-dof pose through a linear map H of their error state.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <limits>

#include "epichead/geometry/se3.h"

namespace epichead::fusion::detail {

using geometry::Matrix6d;
using geometry::Vector6d;

// Computes the correction dx for innovation r with measurement covariance Rm; updates P (Joseph
// form, symmetrised). Returns r' S^-1 r; when it exceeds gate_chi2, P and dx are left untouched
// and `applied` is false.
template <int N>
double kalman_update(Eigen::Matrix<double, N, N>& P, const Eigen::Matrix<double, 6, N>& H, const Vector6d& r,
                     const Matrix6d& Rm, double gate_chi2, Eigen::Matrix<double, N, 1>& dx, bool& applied) {
  const Eigen::Matrix<double, N, 6> PHt = P * H.transpose();
  const Matrix6d S = H * PHt + Rm;
  const Eigen::LLT<Matrix6d> llt(S);
  applied = false;
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  const double d2 = r.dot(llt.solve(r));
  if (!(d2 <= gate_chi2)) return d2;
  // K = P H' S^-1, computed as (S^-1 H P)' since S is symmetric.
  const Eigen::Matrix<double, N, 6> K = llt.solve(PHt.transpose()).transpose();
  dx = K * r;
  Eigen::Matrix<double, N, N> IKH = -K * H;
  IKH.diagonal().array() += 1.0;
  P = IKH * P * IKH.transpose() + K * Rm * K.transpose();
  P = 0.5 * (P + P.transpose()).eval();
  applied = true;
  return d2;
}

}  // namespace epichead::fusion::detail
