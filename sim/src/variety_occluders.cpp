// Scene variety: the occluders: the scene's own shifted, a passing pole, cover boards.
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "variety_steps.h"

namespace epichead::sim::variety {
namespace {

using Eigen::Vector3d;

// Adds an occluder that follows `keys` (positions) with a fixed orientation.
void add_keyed_occluder(Scene& s, Scenario& run, Mesh mesh, const Eigen::Matrix3d& world_R_occluder,
                        const std::vector<std::pair<double, Vector3d>>& keys) {
  const int index = static_cast<int>(s.occluders.size());
  s.occluders.push_back(std::move(mesh));
  OccluderPath path;
  path.world_T_start.linear() = world_R_occluder;
  path.world_T_start.translation() = keys.front().second;
  path.world_T_end = path.world_T_start;
  s.occluder_paths.resize(s.occluders.size() - 1);  // scenes without paths for earlier occluders
  s.occluder_paths.push_back(path);
  for (const auto& [t, p] : keys) run.occluder_keys.push_back({index, t, p});
}

}  // namespace

void vary_occluders(Scene& s, Scenario& run, const Draws& d, double v, SceneVariety& out) {
  out.occluder_time_shift_s = v * symmetric(d.occluder_t);
  out.occluder_shift_m = v * 0.03 * Vector3d(symmetric(d.occluder_x), 0, symmetric(d.occluder_z));
  for (OccluderPath& p : s.occluder_paths) {
    p.start_s = std::max(0.0, p.start_s + out.occluder_time_shift_s);
    p.world_T_start.translation() += out.occluder_shift_m;
    p.world_T_end.translation() += out.occluder_shift_m;
  }
  for (std::size_t i = 0; i < run.occluder_keys.size(); ++i) {
    OccluderKey& k = run.occluder_keys[i];
    k.t_s = std::max(0.0, k.t_s + out.occluder_time_shift_s);
    k.position_world += out.occluder_shift_m;
    // Keys clamped to 0 keep their order.
    for (std::size_t j = 0; j < i; ++j)
      if (run.occluder_keys[j].occluder == k.occluder && k.t_s <= run.occluder_keys[j].t_s)
        k.t_s = run.occluder_keys[j].t_s + 1e-3;
  }
}

void add_pole(Scene& s, Scenario& run, const Rig& rig, const Draws& d, SceneVariety& out) {
  const double t0 = run.frame_time_s(0), t1 = run.frame_time_s(run.frames - 1);
  out.pole = true;
  out.pole_mid_s = t0 + (0.2 + 0.6 * d.pole_mid) * (t1 - t0);
  const double cross_s = 1.5 + 1.5 * d.pole_cross;
  const double f = 0.3 + 0.3 * d.pole_fraction;  // where between object and camera
  const Vector3d obj = s.view.target_world;  // the object's centre (moved with it)
  const Vector3d cam = rig.world_T_cam(out.pole_mid_s).pose.translation();
  const Eigen::AlignedBox3d box = model_box(s);
  const double width = std::min(box.sizes().x(), box.sizes().y());
  // Seen from the camera it covers diameter / (1 - f) of the object's plane.
  out.pole_diameter_m = 0.3 * width * (1 - f) * (0.5 + 0.5 * d.pole_width);
  Vector3d los = cam - obj;
  los.z() = 0;
  const Vector3d across = Vector3d::UnitZ().cross(los).normalized() * (d.pole_side < 0.5 ? 1.0 : -1.0);
  const Vector3d centre = obj + f * (cam - obj);
  const double half_travel = (1 - f) * (cam - obj).norm() * std::tan(35 * deg) + out.pole_diameter_m;
  const double ground = s.shadows.enabled ? s.shadows.ground_z_m : (s.world_T_obj * box.min()).z();
  Mesh pole;
  const float grey = static_cast<float>(0.08 + 0.7 * d.pole_grey);
  Material m;
  m.albedo_bgr = {grey, grey * 0.97f, grey * 0.93f};
  s.materials.push_back(m);
  add_frustum(pole, Eigen::Isometry3d::Identity(), out.pole_diameter_m / 2, out.pole_diameter_m / 2,
              obj.z() - ground + 1.5, 32, Caps::Both, static_cast<int>(s.materials.size()) - 1);
  const Vector3d base(centre.x(), centre.y(), ground);
  add_keyed_occluder(s, run, std::move(pole), Eigen::Matrix3d::Identity(),
                     {{out.pole_mid_s - cross_s / 2, base - half_travel * across},
                      {out.pole_mid_s + cross_s / 2, base + half_travel * across}});
}

void add_cover(Scene& s, Scenario& run, const Rig& rig, const CoverWindow& w) {
  constexpr double slide_s = CoverWindow::kSlideS, depth_m = 0.2, size_m = 0.8, out_m = 0.7, step_s = 1.0 / 120;
  Material m;
  m.albedo_bgr = {0.33f, 0.47f, 0.58f};  // cardboard
  s.materials.push_back(m);
  Mesh board;
  add_box(board, Eigen::Isometry3d::Identity(), {size_m, size_m, 0.01}, static_cast<int>(s.materials.size()) - 1);
  const double t_in = w.start_s - slide_s, t_out = w.start_s + w.duration_s + slide_s;
  const Eigen::Matrix3d world_R_board = rig.world_T_cam(w.start_s + w.duration_s / 2).pose.linear();
  const Vector3d parked(0, 0, 1000);
  std::vector<std::pair<double, Vector3d>> keys;
  if (t_in > 0.002) keys.push_back({t_in - 0.002, parked});
  const int n = static_cast<int>(std::ceil((t_out - t_in) / step_s));
  for (int i = 0; i <= n; ++i) {
    const double t = std::min(t_out, t_in + i * step_s);
    if (t < 0) continue;
    double x = 0;  // camera x of the board's centre: +out_m (out of view) -> 0 -> -out_m
    if (t < w.start_s) x = out_m * (0.5 + 0.5 * std::cos(pi * (t - t_in) / slide_s));
    else if (t > w.start_s + w.duration_s) x = -out_m * (0.5 - 0.5 * std::cos(pi * (t - w.start_s - w.duration_s) / slide_s));
    const Eigen::Isometry3d world_T_cam = rig.world_T_cam(t).pose;
    keys.push_back({t, world_T_cam * Vector3d(x, 0, depth_m)});
  }
  keys.push_back({t_out + 0.002, parked});
  add_keyed_occluder(s, run, std::move(board), world_R_board, keys);
}

}  // namespace epichead::sim::variety
