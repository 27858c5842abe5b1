// Scene variety: draw (one fixed-order set of uniforms per seed and attempt), place the camera
// and the object, check the view, then change the look: background, light, object, occluders.
#include "epichead/sim/scene_variety.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "epichead/sim/rig.h"
#include "epichead/sim/scene_library.h"
#include "scene_photo.h"
#include "simulate_random.h"
#include "texture.h"

namespace epichead::sim {
namespace {

using Eigen::Vector3d;
constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;

// The variety's own random stream: drawing it shifts none of the other streams (trajectory 11,
// 12; IMU 21, 22; init 31; frames 41; bus 51). One stream index per attempt.
constexpr std::uint64_t kVarietyStream = 61;
// Rejected draws (object out of view) are redrawn; after kFullAttempts the jitter is halved per
// further attempt, and after kAttempts the built-in scene is used.
constexpr int kFullAttempts = 8, kAttempts = 14;
// Below this object/background contrast (or the built-in scene's, if lower) the drawn albedo
// is moved away from the background.
constexpr double kMinContrast = 0.15;
constexpr std::size_t kMaxPlanes = 8, kMaxShakes = 8;

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

double symmetric(double u) { return 2 * u - 1; }  // [0, 1) -> [-1, 1)
// A factor in [1/f, f] on a log scale, scaled by the variety.
double factor(double u, double f, double v) { return std::exp(v * symmetric(u) * std::log(f)); }
double wrap_deg(double a) { return std::remainder(a, 360.0); }

// ---- camera path and object placement -------------------------------------------------------

Eigen::AlignedBox3d model_box(const Scene& s) {
  Eigen::AlignedBox3d box;
  for (const Vector3d& p : s.model.vertices) box.extend(p);
  return box;
}

Vector3d& start_of(Scenario& s) {
  return s.motion == MotionKind::walking ? s.walking.start_world
         : s.motion == MotionKind::wheeled ? s.wheeled.start_world
                                           : s.handheld.start_world;
}
double& heading_of(Scenario& s) {
  return s.motion == MotionKind::walking ? s.walking.heading_rad
         : s.motion == MotionKind::wheeled ? s.wheeled.heading_rad
                                           : s.handheld.heading_rad;
}

// The object's pose and the scenario's camera path for one draw at variety v.
void place(const Scene& nominal, const Draws& d, double v, Scenario& run, Eigen::Isometry3d& world_T_obj,
           SceneVariety& out) {
  const VarietyLimits& lim = nominal.variety_limits;
  out.object_yaw_deg = v * symmetric(d.yaw) * lim.object_yaw_deg;
  out.object_offset_m = v * lim.object_offset_m * Eigen::Vector2d(symmetric(d.offset_x), symmetric(d.offset_y));
  world_T_obj = Eigen::Isometry3d::Identity();
  world_T_obj.translation() = Vector3d(out.object_offset_m.x(), out.object_offset_m.y(), 0);
  world_T_obj.linear() = Eigen::AngleAxisd(out.object_yaw_deg * deg, Vector3d::UnitZ()).toRotationMatrix();

  // Start: turned about the object, moved nearer or farther within the view's distance range,
  // shifted a little; the heading turns with the orbit so the body still faces the object.
  const Vector3d target = nominal.view.target_world;
  const Eigen::AngleAxisd orbit(v * symmetric(d.orbit) * lim.orbit_deg * deg, Vector3d::UnitZ());
  Vector3d rel = orbit * (start_of(run) - target);
  const bool on_floor = run.motion != MotionKind::handheld;  // a robot's body height stays
  Vector3d scaled = rel;
  const double f = factor(d.distance, 1.2, v);
  if (on_floor) scaled.head<2>() *= f;
  else scaled *= f;
  const double dist = scaled.norm();
  if (dist > nominal.view.max_distance_m || dist < nominal.view.min_distance_m) scaled = rel;  // keep the built-in distance
  rel = scaled;
  Vector3d start = target + rel;
  start.x() += v * symmetric(d.shift_x) * lim.start_shift_m;
  start.y() += v * symmetric(d.shift_y) * lim.start_shift_m;
  if (!on_floor) start.z() += v * symmetric(d.shift_z) * lim.start_shift_m;
  run.walking.start_world = run.wheeled.start_world = run.handheld.start_world = start;
  const double turn = orbit.angle() * (orbit.axis().z() < 0 ? -1 : 1) + v * symmetric(d.heading) * lim.heading_deg * deg;
  const double heading = heading_of(run) + turn;
  run.walking.heading_rad = run.wheeled.heading_rad = run.handheld.heading_rad = heading;
  run.wheeled.drive_heading_rad += turn;  // the drive turns with the body
  out.start_world = start;
  out.heading_deg = heading / deg;

  // Aim: turned with the orbit and moved by up to a quarter of the object's size.
  if (!run.head_deg) {
    const double size = model_box(nominal).sizes().norm();
    out.aim_shift_m = v * 0.25 * size * Vector3d(symmetric(d.aim[0]), symmetric(d.aim[1]), symmetric(d.aim[2])) / 2;
    const Vector3d aim = run.aim_world.value_or(target);
    run.aim_world = target + orbit * (aim - target) + out.aim_shift_m;
  }

  // Speed, motion amplitude and timing.
  out.speed_scale = factor(d.speed, 1.3, v);
  out.motion_scale = factor(d.motion, 1.3, v);
  out.timing_scale = factor(d.timing, 1.15, v);
  out.path_seed = v > 0 ? d.path_seed : run.walking.seed;
  switch (run.motion) {
    case MotionKind::walking: {
      WalkingParams& w = run.walking;
      w.speed_mps *= out.speed_scale;
      w.burst_min_degps *= out.motion_scale;
      w.burst_max_degps *= out.motion_scale;
      w.bob_m *= out.motion_scale;
      w.step_period_s = std::max(w.step_period_s * out.timing_scale, w.burst_s * 1.2);
      w.first_step_s += v * 0.5 * d.first_step;
      w.seed = out.path_seed;
      break;
    }
    case MotionKind::wheeled: {
      WheeledParams& w = run.wheeled;
      // Never farther than built: the drive stays inside the room.
      w.distance_m *= std::min(1.0, out.speed_scale);
      w.drive_start_s = std::max(0.0, w.drive_start_s + v * 0.5 * symmetric(d.drive_t));
      w.turn.t0_s = std::max(0.0, w.turn.t0_s + v * symmetric(d.turn_t));
      w.turn.peak_rate_radps *= out.motion_scale;
      break;
    }
    case MotionKind::handheld: {
      HandheldParams& h = run.handheld;
      h.sway_hz *= out.speed_scale;
      h.sway_m *= out.motion_scale;
      h.sway_deg *= out.motion_scale;
      for (std::size_t i = 0; i < h.shakes.size(); ++i) {
        h.shakes[i].peak_rate_radps *= out.motion_scale;
        h.shakes[i].t0_s = std::max(0.0, h.shakes[i].t0_s + v * 0.4 * symmetric(d.shake_t[i % kMaxShakes]));
      }
      h.seed = out.path_seed;
      break;
    }
  }
}

// ---- appearance -----------------------------------------------------------------------------

// Mean linear luminance of a gamma-encoded 8-bit BGR texture.
double mean_luminance(const cv::Mat& bgr) {
  cv::Mat small;
  cv::resize(bgr, small, cv::Size(32, 32), 0, 0, cv::INTER_AREA);
  double sum = 0;
  for (int y = 0; y < small.rows; ++y)
    for (int x = 0; x < small.cols; ++x) {
      const cv::Vec3b p = small.at<cv::Vec3b>(y, x);
      sum += 0.114 * std::pow(p[0] / 255.0, 2.2) + 0.587 * std::pow(p[1] / 255.0, 2.2) + 0.299 * std::pow(p[2] / 255.0, 2.2);
    }
  return sum / (small.rows * small.cols);
}
double luminance(const ColorBgr& c) { return 0.114 * c[0] + 0.587 * c[1] + 0.299 * c[2]; }

// Area-weighted mean reflectance of the tracked object's surface.
double object_luminance(const Scene& s) {
  double sum = 0, area = 0;
  const Mesh& m = s.object_mesh;
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const auto& t = m.triangles[i];
    const double a = 0.5 * (m.positions[static_cast<std::size_t>(t[1])] - m.positions[static_cast<std::size_t>(t[0])])
                               .cross(m.positions[static_cast<std::size_t>(t[2])] - m.positions[static_cast<std::size_t>(t[0])])
                               .norm();
    const Material& mat = s.materials[static_cast<std::size_t>(m.triangle_material[i])];
    double l = luminance(mat.albedo_bgr);
    if (mat.texture >= 0) l *= mean_luminance(s.textures[static_cast<std::size_t>(mat.texture)]);
    sum += a * l;
    area += a;
  }
  return area > 0 ? sum / area : 0;
}

// Mean reflectance of what is behind the object: the environment planes, equally weighted.
double background_luminance(const Scene& s) {
  if (s.background.planes.empty()) return luminance(s.background.plain_bgr);
  double sum = 0;
  for (const EnvironmentPlane& p : s.background.planes) {
    double l = luminance(p.tint_bgr);
    if (p.texture >= 0) l *= mean_luminance(s.textures[static_cast<std::size_t>(p.texture)]);
    sum += l;
  }
  return sum / static_cast<double>(s.background.planes.size());
}

double michelson(double a, double b) { return std::abs(a - b) / std::max(a + b, 1e-9); }

// The textures a background plane can show. Walls: every photo and procedural texture; floors
// (planes that receive shadows): the ones a table top or floor could be.
const std::array<const char*, 9> kWallTextures = {"board.jpg", "building.jpg", "stuff.jpg", "graf1.jpg", "clutter",
                                                  "wood",      "concrete",     "plaster",   "parquet"};
const std::array<const char*, 5> kFloorTextures = {"wood", "concrete", "parquet", "stuff.jpg", "board.jpg"};

// Makes the named texture (a built-in photo or a procedural one); sets how densely it is drawn
// on the plane.
std::expected<cv::Mat, std::string> background_texture(const std::string& name, bool floor, std::uint64_t seed,
                                                       const std::array<double, 3>& colour, double& px_per_m) {
  if (name.ends_with(".jpg")) {
    auto img = scene_photo(name);
    if (!img) return std::unexpected(img.error());
    px_per_m = floor ? img->cols / 0.6 : 0;  // a floor: 0.6 m tiles; a wall: stretched over it
    return *img;
  }
  if (name == "clutter") { px_per_m = floor ? 600 : 0; return texture::clutter({1024, 640}, seed); }
  if (name == "wood") { px_per_m = floor ? 800 : 500; return texture::wood({512, 512}, seed); }
  if (name == "concrete") { px_per_m = 400; return texture::concrete({512, 512}, seed); }
  if (name == "parquet") { px_per_m = 400; return texture::parquet({1024, 1024}, seed); }
  px_per_m = 200;
  return texture::plaster({512, 512}, cv::Scalar(120 + 130 * colour[0], 120 + 130 * colour[1], 120 + 130 * colour[2]), seed);
}

std::expected<void, std::string> vary_background(Scene& s, const Draws& d, double v, SceneVariety& out) {
  for (std::size_t i = 0; i < s.background.planes.size(); ++i) {
    EnvironmentPlane& p = s.background.planes[i];
    const std::size_t k = i % kMaxPlanes;
    std::string shown = "built-in";
    if (p.texture >= 0 && d.plane_swap[k] < v) {
      const bool floor = p.receives_shadow;
      const std::size_t n = floor ? kFloorTextures.size() : kWallTextures.size();
      shown = floor ? kFloorTextures[static_cast<std::size_t>(d.plane_pick[k] * n)]
                    : kWallTextures[static_cast<std::size_t>(d.plane_pick[k] * n)];
      double px_per_m = 0;
      auto tex = background_texture(shown, floor, d.plane_seed[k], d.plane_colour, px_per_m);
      if (!tex) return std::unexpected(tex.error());
      s.textures.push_back(std::move(*tex));
      p.texture = static_cast<int>(s.textures.size()) - 1;
      p.tex_px_per_m = px_per_m;
    }
    const float gain = static_cast<float>(factor(d.plane_gain[k], 1.35, v));
    p.tint_bgr = (p.tint_bgr * gain).cwiseMin(1.f);
    out.plane_textures.push_back(shown);
    out.plane_gains.push_back(gain);
  }
  const ColorBgr drawn(static_cast<float>(0.15 + 0.75 * d.background[0]), static_cast<float>(0.15 + 0.75 * d.background[1]),
                       static_cast<float>(0.15 + 0.75 * d.background[2]));
  s.background.plain_bgr += static_cast<float>(v) * (drawn - s.background.plain_bgr);
  out.background_bgr = s.background.plain_bgr;
  return {};
}

void vary_light(Scene& s, Scenario& run, const Draws& d, double v, SceneVariety& out) {
  const Vector3d n = s.light.direction_world.normalized();
  const double az0 = std::atan2(n.y(), n.x()) / deg, el0 = std::asin(std::clamp(n.z(), -1.0, 1.0)) / deg;
  const double az = az0 + v * wrap_deg(360 * d.light_az - az0);
  const double el = el0 + v * (25 + 50 * d.light_el - el0);
  s.light.direction_world = Vector3d(std::cos(el * deg) * std::cos(az * deg), std::cos(el * deg) * std::sin(az * deg),
                                     std::sin(el * deg));
  const double total = s.light.ambient + s.light.diffuse;
  const double a0 = s.light.ambient / total;
  const double a = a0 + v * (0.25 + 0.35 * d.light_ambient - a0);
  // Overall gain x0.6 .. x1.3 (log-uniform around 1 at full variety).
  const double gain = std::exp(v * (std::log(0.6) + d.light_gain * (std::log(1.3) - std::log(0.6))));
  s.light.ambient = a * total * gain;
  s.light.diffuse = (1 - a) * total * gain;
  out.light_azimuth_deg = wrap_deg(az);
  out.light_elevation_deg = el;
  out.light_ambient = s.light.ambient;
  out.light_diffuse = s.light.diffuse;
  out.light_gain = gain;

  // A slow drift of the light level on top of the scenario's keys: keys every second and at the
  // scenario's own key times, each the scenario's level times the drift.
  out.light_drift = v * 0.15 * d.drift;
  out.light_drift_period_s = 5 + 10 * d.drift_period;
  if (out.light_drift < 0.005) { out.light_drift = 0; return; }
  const double phase = 2 * pi * d.drift_phase;
  const double t_end = run.frame_time_s(run.frames - 1) + 1;
  std::vector<double> times;
  for (double t = 0; t <= t_end; t += 1) times.push_back(t);
  for (const LightKey& k : run.light) times.push_back(k.t_s);
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end(), [](double p, double q) { return std::abs(p - q) < 1e-6; }), times.end());
  std::vector<LightKey> keys;
  for (double t : times)
    keys.push_back({t, run.light_gain(t) * (1 + out.light_drift * std::sin(2 * pi * t / out.light_drift_period_s + phase))});
  run.light = std::move(keys);
}

void vary_object(Scene& s, const Draws& d, double v, double builtin_contrast, SceneVariety& out) {
  std::vector<bool> is_object(s.materials.size(), false);
  for (int m : s.object_mesh.triangle_material) is_object[static_cast<std::size_t>(m)] = true;
  const double before = object_luminance(s);
  double scale = factor(d.albedo, 1.5, v);
  out.tint_bgr = ColorBgr(static_cast<float>(factor(d.tint[0], 1.15, v)), static_cast<float>(factor(d.tint[1], 1.15, v)),
                          static_cast<float>(factor(d.tint[2], 1.15, v)));
  // Contrast guard: never below the built-in scene's contrast or kMinContrast, whichever is
  // lower; if the draw is below it, move the albedo to the nearer luminance that has it
  // (darker when brighter would saturate).
  const double tint_l = luminance(out.tint_bgr);
  const double lb = background_luminance(s);
  const double lo = before * scale * tint_l;
  const double need = std::min(kMinContrast, builtin_contrast);
  const std::vector<Material> built = s.materials;
  auto apply = [&](double k) {
    for (std::size_t m = 0; m < s.materials.size(); ++m)
      if (is_object[m])
        s.materials[m].albedo_bgr = (built[m].albedo_bgr.cwiseProduct(out.tint_bgr) * static_cast<float>(k)).cwiseMin(1.f);
    return michelson(object_luminance(s), lb);
  };
  out.contrast = apply(scale);
  if (out.contrast < need && lo > 0) {
    // Saturated albedos (clamped at 1) can leave a brightened object short of the contrast:
    // then darker it is.
    const double brighter = lb * (1 + need) / (1 - need) * 1.01, darker = lb * (1 - need) / (1 + need) / 1.01;
    const bool brighten = std::abs(std::log(brighter / lo)) < std::abs(std::log(darker / lo));
    out.contrast = apply(scale * (brighten ? brighter : darker) / lo);
    if (brighten && out.contrast < need) out.contrast = apply(scale * darker / lo), scale *= darker / lo;
    else scale *= (brighten ? brighter : darker) / lo;
    out.contrast_raised = true;
  }
  out.albedo_scale = scale;
}

// ---- occluders ------------------------------------------------------------------------------

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

// A vertical pole passing between camera and object, at most ~30 % of the object's width.
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

// A board that slides in front of the camera and hides the object for the window, then slides
// out: posed relative to the moving camera (keys every 1/120 s), parked far above the scene
// before and after.
void add_cover(Scene& s, Scenario& run, const Rig& rig, const CoverWindow& w) {
  constexpr double slide_s = 0.3, depth_m = 0.2, size_m = 0.8, out_m = 0.7, step_s = 1.0 / 120;
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

double object_view_margin_px(const Scenario& s, const Scene& scene, const vision::Camera& camera) {
  const Rig rig = Rig::from_scenario(s, scene.view.target_world, scene.world_T_obj);
  const Vector3d centre_obj = scene.world_T_obj.inverse() * scene.view.target_world;
  double worst = 1e9;
  for (int i = 0; i < s.frames; ++i) {
    const Vector3d p = rig.cam_T_obj(s.frame_time_s(i)) * centre_obj;
    if (p.z() < 0.05) return -1e9;
    const Eigen::Vector2d uv = camera.project(p);
    worst = std::min({worst, uv.x(), uv.y(), camera.width_px() - 1 - uv.x(), camera.height_px() - 1 - uv.y()});
  }
  return worst;
}

std::expected<ScenarioScene, std::string> make_scenario_scene(const Scenario& s) {
  auto nominal = make_scene(s.scene);
  if (!nominal) return std::unexpected(nominal.error());
  if (s.variety <= 0 && s.covers.empty()) return ScenarioScene{std::move(*nominal), s, {}};
  auto camera = scenario_camera(s);
  if (!camera) return std::unexpected(camera.error());

  // Camera path and placement first: they decide whether the object stays in view.
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
    trial.min_border_px = object_view_margin_px(run, probe, *camera);
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
    v.min_border_px = object_view_margin_px(s, *nominal, *camera);
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
