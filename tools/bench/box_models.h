#pragma once
// Box-shaped models the benchmarks build in memory: the tea box, a grid of 25 boxes.
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

// The tea box of ../shared/data/teabox: 0.165 x 0.068 x 0.08 m.
inline vision::CadModel teabox_model() {
  vision::RawModel raw;
  add_box(raw, {0, 0, -0.08}, {0.165, 0.068, 0});
  return *vision::build_model(raw, "teabox");
}

// 25 boxes of three heights on a 5 x 5 grid: 300 edges, 150 faces.
inline vision::CadModel box_grid_300_model() {
  vision::RawModel raw;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      add_box(raw, {0.12 * i, 0.12 * j, 0}, {0.12 * i + 0.08, 0.12 * j + 0.08, 0.05 + 0.02 * ((i + j) % 3)});
  return *vision::build_model(raw, "grid300");
}

}  // namespace epichead::bench
