#include "epichead/fusion/free_direction.h"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace epichead::fusion {

std::optional<FreeDirection> find_free_direction(const geometry::Matrix6d& cov) {
  const Eigen::SelfAdjointEigenSolver<geometry::Matrix6d> eig(cov);
  if (eig.info() != Eigen::Success) return std::nullopt;
  const geometry::Vector6d& l = eig.eigenvalues();  // ascending
  if (!(l(4) > 0) || !(l(5) >= kFreeDirectionMinRatio * l(4))) return std::nullopt;
  const geometry::Vector6d u = eig.eigenvectors().col(5);
  const double turn_sigma = std::sqrt(l(5)) * u.tail<3>().norm();
  if (!(turn_sigma >= kFreeDirectionMinTurnSigmaRad)) return std::nullopt;
  FreeDirection f;
  f.direction = u;
  f.measured = eig.eigenvectors();  // ascending: the five measured directions first, the free one last
  f.variances = l;
  f.turn_sigma_rad = turn_sigma;
  return f;
}

geometry::Matrix6d with_free_turn_fixed(const geometry::Matrix6d& cov, const FreeDirection& free) {
  const double scale = kFreeTurnStartSigmaRad / free.turn_sigma_rad;
  const double lowered = free.variances(5) * scale * scale;
  geometry::Matrix6d out = cov + (lowered - free.variances(5)) * free.direction * free.direction.transpose();
  return 0.5 * (out + out.transpose());
}

}  // namespace epichead::fusion
