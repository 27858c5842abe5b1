// Scene variety: draw (one fixed-order set of uniforms per seed and attempt), place the camera
// and the object, check the view, then change the look: background, light, object, occluders.
#include "epichead/sim/scene_variety.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "epichead/sim/rig.h"
#include "epichead/sim/scene_library.h"
#include "simulate_random.h"
#include "variety_steps.h"

namespace epichead::sim {
namespace {

using Eigen::Vector3d;
using namespace variety;

// The variety's own random stream: drawing it shifts none of the other streams (trajectory 11,
// 12; IMU 21, 22; init 31; frames 41; bus 51). One stream index per attempt.
constexpr std::uint64_t kVarietyStream = 61;
// Rejected draws (object out of view) are redrawn; after kFullAttempts the jitter is halved per
// further attempt, and after kAttempts the built-in scene is used.
constexpr int kFullAttempts = 8, kAttempts = 14;

Draws draw(std::uint64_t seed, int attempt) {
  Random r(seed, kVarietyStream, static_cast<std::uint64_t>(attempt));
  Draws d;
  for (std::size_t i = 0; i < kMaxPlanes; ++i) {
    d.plane_swap[i] = r.uniform();
    d.plane_pick[i] = r.uniform();
    d.plane_gain[i] = r.uniform();
    d.plane_seed[i] = 1000 + r.next_u64() % 1000000;
  }
  for (double& v : d.plane_colour) v = r.uniform();
  for (double& v : d.background) v = r.uniform();
  d.light_az = r.uniform(), d.light_el = r.uniform(), d.light_ambient = r.uniform(), d.light_gain = r.uniform();
  d.drift = r.uniform(), d.drift_period = r.uniform(), d.drift_phase = r.uniform();
  d.albedo = r.uniform(), d.print_swap = r.uniform();
  for (double& v : d.tint) v = r.uniform();
  d.print_seed = 1 + r.next_u64() % 1000000;
  d.yaw = r.uniform(), d.offset_x = r.uniform(), d.offset_y = r.uniform();
  d.orbit = r.uniform(), d.distance = r.uniform(), d.shift_x = r.uniform(), d.shift_y = r.uniform();
  d.shift_z = r.uniform(), d.heading = r.uniform();
  for (double& v : d.aim) v = r.uniform();
  d.speed = r.uniform(), d.motion = r.uniform(), d.timing = r.uniform(), d.first_step = r.uniform();
  d.turn_t = r.uniform(), d.drive_t = r.uniform();
  for (double& v : d.shake_t) v = r.uniform();
  d.path_seed = 1 + r.next_u64() % 1000000;
  d.occluder_t = r.uniform(), d.occluder_x = r.uniform(), d.occluder_z = r.uniform();
  d.pole = r.uniform(), d.pole_mid = r.uniform(), d.pole_cross = r.uniform(), d.pole_fraction = r.uniform();
  d.pole_width = r.uniform(), d.pole_side = r.uniform(), d.pole_grey = r.uniform();
  return d;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
template <typename V>
std::string list(const V& v) {
  std::string s = "[";
  for (int i = 0; i < static_cast<int>(v.size()); ++i) s += (i ? ", " : "") + num(static_cast<double>(v[i]));
  return s + "]";
}

}  // namespace

namespace {
// The object centre's distance from the image border at frame i (-1e9 behind the camera).
struct CentreMargin {
  Rig rig;
  Vector3d centre_obj;
  double at(const Scenario& s, const vision::Camera& camera, int i) const {
    const Vector3d p = rig.cam_T_obj(s.frame_time_s(i)) * centre_obj;
    if (p.z() < 0.05) return -1e9;
    const Eigen::Vector2d uv = camera.project(p);
    return std::min({uv.x(), uv.y(), camera.width_px() - 1 - uv.x(), camera.height_px() - 1 - uv.y()});
  }
};
CentreMargin centre_margin(const Scenario& s, const Scene& scene) {
  return {Rig::from_scenario(s, scene.view.target_world, scene.world_T_obj),
          scene.world_T_obj.inverse() * scene.view.target_world};
}
}  // namespace

double object_view_margin_px(const Scenario& s, const Scene& scene, const vision::Camera& camera,
                             const std::vector<unsigned char>* frames) {
  const CentreMargin m = centre_margin(s, scene);
  double worst = 1e9;
  for (int i = 0; i < s.frames; ++i) {
    if (frames && (static_cast<std::size_t>(i) >= frames->size() || !(*frames)[static_cast<std::size_t>(i)])) continue;
    worst = std::min(worst, m.at(s, camera, i));
    if (worst <= -1e9) return worst;
  }
  return worst;
}

std::vector<unsigned char> frames_in_view(const Scenario& s, const Scene& scene, const vision::Camera& camera) {
  const CentreMargin m = centre_margin(s, scene);
  std::vector<unsigned char> in(static_cast<std::size_t>(std::max(0, s.frames)));
  for (int i = 0; i < s.frames; ++i) in[static_cast<std::size_t>(i)] = m.at(s, camera, i) >= kMinBorderPx;
  return in;
}

std::expected<ScenarioScene, std::string> make_scenario_scene(const Scenario& s) {
  auto nominal = make_scene(s.scene);
  if (!nominal) return std::unexpected(nominal.error());
  if (s.variety <= 0 && s.covers.empty()) return ScenarioScene{std::move(*nominal), s, {}};
  auto camera = scenario_camera(s);
  if (!camera) return std::unexpected(camera.error());

  // Camera path and placement first: they decide whether the object stays in view (in the
  // frames where the built-in scene keeps it in view).
  const std::vector<unsigned char> in_view = frames_in_view(s, *nominal, *camera);
  ScenarioScene out{{}, s, {}};
  SceneVariety& v = out.drawn;
  v.variety = s.variety;
  Draws d;
  Eigen::Isometry3d world_T_obj = Eigen::Isometry3d::Identity();
  bool found = s.variety <= 0;
  for (int attempt = 0; !found && attempt < kAttempts; ++attempt) {
    const double applied = s.variety * (attempt < kFullAttempts ? 1.0 : std::pow(0.5, attempt - kFullAttempts + 1));
    SceneVariety trial;
    Scenario run = s;
    d = draw(s.seed, attempt);
    place(*nominal, d, applied, run, world_T_obj, trial);
    Scene probe = *nominal;  // textures are shared, not copied
    probe.world_T_obj = world_T_obj;
    probe.view.target_world = world_T_obj * nominal->view.target_world;
    trial.min_border_px = object_view_margin_px(run, probe, *camera, &in_view);
    if (trial.min_border_px >= kMinBorderPx) {
      found = true;
      trial.variety = s.variety;
      trial.attempt = attempt;
      trial.applied = applied;
      v = trial;
      out.scenario = run;
    }
  }
  if (!found || s.variety <= 0) {  // the built-in path (no variety, or no draw kept the object in view)
    out.scenario = s;
    v = SceneVariety{};
    v.variety = s.variety;
    v.attempt = s.variety <= 0 ? 0 : kAttempts;
    world_T_obj = Eigen::Isometry3d::Identity();
    d = draw(s.seed, 0);
    v.min_border_px = object_view_margin_px(s, *nominal, *camera, &in_view);
  }
  const double applied = v.applied;
  Scenario& run = out.scenario;

  // The look.
  const double builtin_contrast = michelson(object_luminance(*nominal), background_luminance(*nominal));
  v.print_seed = applied > 0 && d.print_swap < applied ? d.print_seed : 0;
  if (v.print_seed != 0) {
    auto reprinted = make_scene(s.scene, v.print_seed);
    if (!reprinted) return std::unexpected(reprinted.error());
    out.scene = std::move(*reprinted);
  } else {
    out.scene = std::move(*nominal);
  }
  Scene& scene = out.scene;
  scene.world_T_obj = world_T_obj;
  scene.view.target_world = world_T_obj * scene.view.target_world;
  scene.view.camera_world = world_T_obj * scene.view.camera_world;
  if (applied > 0) {
    if (auto ok = vary_background(scene, d, applied, v); !ok) return std::unexpected(ok.error());
    vary_light(scene, run, d, applied, v);
    vary_object(scene, d, applied, builtin_contrast, v);
    v.builtin_contrast = builtin_contrast;
    vary_occluders(scene, run, d, applied, v);
  }
  const Rig rig = Rig::from_scenario(run, scene.view.target_world, scene.world_T_obj);
  if (applied > 0 && scene.variety_limits.passing_pole && scene.occluders.empty() && d.pole < 0.7 * applied)
    add_pole(scene, run, rig, d, v);
  for (const CoverWindow& w : s.covers) add_cover(scene, run, rig, w);
  v.covers = static_cast<int>(s.covers.size());
  return out;
}

std::string to_json(const SceneVariety& v, const std::string& in) {
  const std::string i2 = in + "  ";
  std::string t = "{\n";
  auto field = [&](const std::string& key, const std::string& value, bool last = false) {
    t += i2 + "\"" + key + "\": " + value + (last ? "\n" : ",\n");
  };
  field("variety", num(v.variety));
  field("applied", num(v.applied));
  field("rejected_draws", std::to_string(v.attempt));
  std::string planes = "[";
  for (std::size_t i = 0; i < v.plane_textures.size(); ++i) planes += (i ? ", \"" : "\"") + v.plane_textures[i] + "\"";
  field("plane_textures", planes + "]");
  field("plane_gains", list(v.plane_gains));
  field("background_bgr", list(v.background_bgr));
  field("light_azimuth_deg", num(v.light_azimuth_deg));
  field("light_elevation_deg", num(v.light_elevation_deg));
  field("light_ambient", num(v.light_ambient));
  field("light_diffuse", num(v.light_diffuse));
  field("light_gain", num(v.light_gain));
  field("light_drift", num(v.light_drift));
  field("light_drift_period_s", num(v.light_drift_period_s));
  field("object_albedo_scale", num(v.albedo_scale));
  field("object_tint_bgr", list(v.tint_bgr));
  field("object_print_seed", std::to_string(v.print_seed));
  field("object_contrast", num(v.contrast));
  field("builtin_contrast", num(v.builtin_contrast));
  field("contrast_raised", v.contrast_raised ? "true" : "false");
  field("object_yaw_deg", num(v.object_yaw_deg));
  field("object_offset_m", list(v.object_offset_m));
  field("start_world", list(v.start_world));
  field("heading_deg", num(v.heading_deg));
  field("aim_shift_m", list(v.aim_shift_m));
  field("speed_scale", num(v.speed_scale));
  field("motion_scale", num(v.motion_scale));
  field("timing_scale", num(v.timing_scale));
  field("path_seed", std::to_string(v.path_seed));
  field("occluder_time_shift_s", num(v.occluder_time_shift_s));
  field("occluder_shift_m", list(v.occluder_shift_m));
  field("pole", v.pole ? "true" : "false");
  field("pole_mid_s", num(v.pole_mid_s));
  field("pole_diameter_m", num(v.pole_diameter_m));
  field("covers", std::to_string(v.covers));
  field("min_border_px", num(v.min_border_px), true);
  return t + in + "}";
}

}  // namespace epichead::sim
