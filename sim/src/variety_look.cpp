// Scene variety: the look: background textures and colours, light, the object's albedo and tint.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "scene_photo.h"
#include "texture.h"
#include "variety_steps.h"

namespace epichead::sim::variety {
namespace {

using Eigen::Vector3d;

// Below this object/background contrast (or the built-in scene's, if lower) the drawn albedo
// is moved away from the background.
constexpr double kMinContrast = 0.15;

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

}  // namespace

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

}  // namespace epichead::sim::variety
