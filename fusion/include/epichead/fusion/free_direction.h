#pragma once
// A direction of the pose that vision does not measure: a body of revolution's turn about its
// axis, which the pose estimator leaves at the prediction and gives a stand-in sigma of 1 rad
// (vision::PoseProblem::free_turn). It shows in the pose's covariance as one eigenvalue far above
// the others whose direction is mostly a turn.
//
// A linearised filter must not take such a direction as a measurement with a huge variance, nor
// start from it. Started from it, the filter holds the object's turn to +-1 rad; each update, whose
// own free direction differs from the filter's by the tiny change of the pose, then reads a turn
// out of that difference, divided by it: on the onboard loop's lamp shade (sim-run lampshade
// --seed 220) the second pose, 1 mm from the prediction, moved the filter's pose 38 mm, the
// velocity and gravity learnt the jump, every pose after it was gated, 3.7 % success. So:
//   - an update measures the five other directions only (the innovation and covariance projected
//     onto them): the pose's turn, wherever it was left, never pulls the filter nor gates a pose;
//   - a filter started from such a pose gives the turn kFreeTurnStartSigmaRad, a gauge: which turn of a
//     body that looks the same at every turn the filter holds is arbitrary, and the gyro carries it.
#include <optional>

#include "epichead/geometry/se3.h"

namespace epichead::fusion {

// Free: the covariance's largest eigenvalue at least this many times the next ...
inline constexpr double kFreeDirectionMinRatio = 1e3;
// ... with at least this much turn along it (a pose whose depth alone is loose is not free).
inline constexpr double kFreeDirectionMinTurnSigmaRad = 0.2;
// The turn's sigma a filter started from such a pose holds.
inline constexpr double kFreeTurnStartSigmaRad = 0.05;

struct FreeDirection {
  geometry::Vector6d direction;        // unit, left perturbation (translation, rotation)
  geometry::Matrix6d measured;         // columns 0-4: the other eigenvectors (unit), column 5: direction
  geometry::Vector6d variances;        // along each column of `measured`
  double turn_sigma_rad = 0;           // the turn's sigma the covariance gives along `direction`
};

// The covariance's free direction (kFreeDirectionMinRatio, kFreeDirectionMinTurnSigmaRad), or nothing.
std::optional<FreeDirection> find_free_direction(const geometry::Matrix6d& cov);

// `cov` with the free direction's sigma brought to kFreeTurnStartSigmaRad of turn.
geometry::Matrix6d with_free_turn_fixed(const geometry::Matrix6d& cov, const FreeDirection& free);

// `cov` with its free direction's turn at kFreeTurnStartSigmaRad, or `cov` when it has none.
inline geometry::Matrix6d start_covariance(const geometry::Matrix6d& cov) {
  const auto free = find_free_direction(cov);
  return free ? with_free_turn_fixed(cov, *free) : cov;
}

}  // namespace epichead::fusion
