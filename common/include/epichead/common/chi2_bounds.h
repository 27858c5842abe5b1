#pragma once
// The band that holds 95 % of chi-square with 5 or 6 degrees of freedom (its 2.5 % and 97.5 %
// quantiles): where an honest pose's normalised error squared lies, against the truth (NEES,
// `score --covariance`) or against a filter's prediction (NIS, `track --imu on`). 6 degrees, or 5
// when a body of revolution's turn about its axis is left out.
#include <stdexcept>

namespace epichead::common {

struct Chi2Bounds {
  double low, high;  // 2.5 % and 97.5 % quantiles
};

// Throws std::invalid_argument for any other number of degrees of freedom.
inline Chi2Bounds chi2_95_bounds(int dof) {
  if (dof == 5) return {0.8312, 12.8325};
  if (dof == 6) return {1.2373, 14.4494};
  throw std::invalid_argument("chi2_95_bounds: dof must be 5 or 6");
}

}  // namespace epichead::common
