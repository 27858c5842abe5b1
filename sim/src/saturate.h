#pragma once
// An IMU's range: a reading beyond it comes out at the range (what the simulated sensor and its
// firmware node both do).
#include <cmath>

#include <Eigen/Core>

namespace epichead::sim {

// Clips each axis to +-range; true when any axis was clipped.
inline bool saturate(Eigen::Vector3d& v, double range) {
  bool clipped = false;
  for (int i = 0; i < 3; ++i) {
    if (std::abs(v[i]) > range) {
      v[i] = std::copysign(range, v[i]);
      clipped = true;
    }
  }
  return clipped;
}

}  // namespace epichead::sim
