#pragma once
// Box-shaped models the benchmarks build in memory (the tea box, a grid of 25 boxes).
#include <Eigen/Core>

#include "epichead/vision/cao_model.h"

namespace epichead::bench {

// An axis-aligned box as closed faces: 8 vertices, 6 faces counter-clockwise from outside.
inline void add_box(vision::RawModel& raw, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const int b = static_cast<int>(raw.vertices.size());
  for (int i = 0; i < 8; ++i)
    raw.vertices.emplace_back(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z());
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& f : faces) raw.face_loops.push_back({b + f[0], b + f[1], b + f[2], b + f[3]});
}

}  // namespace epichead::bench
