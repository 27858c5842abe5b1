#pragma once
// Private to scene variety (scene_variety.cpp): the uniforms a draw takes, and the steps that apply
// them in the order make_scenario_scene runs them: placement and camera path (variety_place.cpp),
// the look (variety_look.cpp), the occluders (variety_occluders.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <expected>
#include <numbers>
#include <string>

#include <Eigen/Geometry>

#include "epichead/sim/rig.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene.h"
#include "epichead/sim/scene_variety.h"

namespace epichead::sim::variety {

inline constexpr double pi = std::numbers::pi;
inline constexpr double deg = pi / 180.0;
inline constexpr std::size_t kMaxPlanes = 8, kMaxShakes = 8;

// Every uniform a draw uses, drawn in this order whatever the scene, so that each parameter has
// a fixed place in the stream. All in [0, 1) unless named otherwise.
struct Draws {
  std::array<double, kMaxPlanes> plane_swap{}, plane_pick{}, plane_gain{};
  std::array<std::uint64_t, kMaxPlanes> plane_seed{};
  std::array<double, 3> plane_colour{}, background{};
  double light_az = 0, light_el = 0, light_ambient = 0, light_gain = 0, drift = 0, drift_period = 0, drift_phase = 0;
  double albedo = 0, print_swap = 0;
  std::array<double, 3> tint{};
  std::uint64_t print_seed = 0;
  double yaw = 0, offset_x = 0, offset_y = 0;
  double orbit = 0, distance = 0, shift_x = 0, shift_y = 0, shift_z = 0, heading = 0;
  std::array<double, 3> aim{};
  double speed = 0, motion = 0, timing = 0, first_step = 0, turn_t = 0, drive_t = 0;
  std::array<double, kMaxShakes> shake_t{};
  std::uint64_t path_seed = 0;
  double occluder_t = 0, occluder_x = 0, occluder_z = 0;
  double pole = 0, pole_mid = 0, pole_cross = 0, pole_fraction = 0, pole_width = 0, pole_side = 0, pole_grey = 0;
};

inline double symmetric(double u) { return 2 * u - 1; }  // [0, 1) -> [-1, 1)
// A factor in [1/f, f] on a log scale, scaled by the variety.
inline double factor(double u, double f, double v) { return std::exp(v * symmetric(u) * std::log(f)); }
inline double wrap_deg(double a) { return std::remainder(a, 360.0); }
// Michelson contrast of two luminances.
inline double michelson(double a, double b) { return std::abs(a - b) / std::max(a + b, 1e-9); }

// variety_place.cpp. The box around the tracked object's model (object frame).
Eigen::AlignedBox3d model_box(const Scene& s);
// The object's pose and the scenario's camera path for one draw at variety v.
void place(const Scene& nominal, const Draws& d, double v, Scenario& run, Eigen::Isometry3d& world_T_obj,
           SceneVariety& out);

// variety_look.cpp. Area-weighted mean reflectance of the tracked object's surface.
double object_luminance(const Scene& s);
// Mean reflectance of what is behind the object: the environment planes, equally weighted.
double background_luminance(const Scene& s);
// Textures and brightness of the environment planes, the plain background colour.
std::expected<void, std::string> vary_background(Scene& s, const Draws& d, double v, SceneVariety& out);
// Light direction, ambient/diffuse split and gain, and a slow drift added to the scenario's light keys.
void vary_light(Scene& s, Scenario& run, const Draws& d, double v, SceneVariety& out);
// The object's albedo scale and tint, kept at a minimum contrast against the background.
void vary_object(Scene& s, const Draws& d, double v, double builtin_contrast, SceneVariety& out);

// variety_occluders.cpp. The scene's own occluders: shifted in time and place.
void vary_occluders(Scene& s, Scenario& run, const Draws& d, double v, SceneVariety& out);
// A vertical pole passing between camera and object, at most ~30 % of the object's width.
void add_pole(Scene& s, Scenario& run, const Rig& rig, const Draws& d, SceneVariety& out);
// A board that slides in front of the camera and hides the object for the window, then slides
// out: posed relative to the moving camera (keys every 1/120 s), parked far above the scene
// before and after.
void add_cover(Scene& s, Scenario& run, const Rig& rig, const CoverWindow& w);

}  // namespace epichead::sim::variety
