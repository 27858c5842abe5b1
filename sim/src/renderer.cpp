// The simulator's renderer. Why it is hand-written: OpenCV's fillPoly has no depth buffer, no
// sub-pixel anti-aliasing and no perspective-correct attributes, and a GL context is not
// available on a headless robot or in CI. Per frame:
//   1. environment (photos on far walls, the floor) at pixel resolution: each visible plane
//      warped along its polygon's row spans (a plane maps by a homography), cast shadows as
//      filled polygons; drawn at as few instants of the exposure as its own image motion needs,
//      averaged, row by row over all instants (render_environment.h);
//   2. per sub-frame, objects (tracked object, scenery, occluders) rasterised exactly
//      (fixed-point edge functions, top-left rule) at several sub-pixel sample positions with a
//      depth buffer, tile by tile, shaded once per pixel and triangle (multisampling); each
//      pixel adds (its samples - the environment behind them) / samples / sub-frames;
//   3. gain, gamma (a table), lens distortion, noise.
// Everything is drawn in an undistorted "ideal" pinhole image that covers the real image; lens
// distortion is applied once per frame by remapping with a precomputed map. Straight 3D edges
// stay straight until then, so vertices and edges land where Camera::project puts them (to the
// map's 1/32 px).
#include "epichead/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "renderer_impl.h"

namespace epichead::sim {
namespace {

using render::kMaxSamplesPerFrame;
using render::kMaxSamplesPerSubframe;
using render::kTile;

}  // namespace

Renderer::Impl::Impl(Scene s, const vision::Camera& cam, const RenderOptions& o)
    : scene(std::move(s)), camera(cam), opt(o) {
  validate();
  M = std::clamp(opt.samples_per_subframe, 1, kMaxSamplesPerSubframe);
  setup_ideal_camera();
  setup_tables();
  setup_textures();
  const std::size_t n = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  depth.assign(static_cast<std::size_t>(kTile * kTile * M), 0.f);
  color.assign(static_cast<std::size_t>(kTile * kTile * M * 3), 0.f);
  env_linear.assign(n * 3, 0.f);
  corr.create(H, W, CV_32FC3);
  encoded.create(H, W, CV_32FC3);
  if (distort) remapped.create(camera.height_px(), camera.width_px(), CV_32FC3);
  std::size_t triangles = scene.object_mesh.triangles.size();
  for (const auto& m : scene.scenery) triangles += m.triangles.size();
  for (const auto& m : scene.occluders) triangles += m.triangles.size();
  tris.reserve(3 * triangles + 16);
  materials.resize(scene.materials.size());
  patterns.resize(kMaxSamplesPerFrame + 1);
  // Clip planes: near, and a guard band around the ideal image (keeps fixed point in range).
  render::IdealView view;
  view.W = W; view.H = H; view.fx = fx; view.fy = fy; view.cx = cx; view.cy = cy;
  view.set_clip_planes(opt.near_m);
  std::copy(std::begin(view.clip_planes), std::end(view.clip_planes), clip_planes);
  environment.emplace(scene, view, opt.gamma > 0 ? opt.gamma : 1.0, decode_lut);
  env_instants.reserve(16);
}

void Renderer::Impl::validate() const {
  const int n_mat = static_cast<int>(scene.materials.size());
  const int n_tex = static_cast<int>(scene.textures.size());
  auto check_mesh = [&](const Mesh& m, const char* what) {
    if (m.normals.size() != m.positions.size() || m.triangle_material.size() != m.triangles.size())
      throw std::invalid_argument(std::string("renderer: ") + what + ": attribute arrays differ in size");
    for (const auto& t : m.triangles)
      for (int v : t)
        if (v < 0 || v >= static_cast<int>(m.positions.size()))
          throw std::invalid_argument(std::string("renderer: ") + what + ": vertex index out of range");
    for (int mat : m.triangle_material)
      if (mat < 0 || mat >= n_mat) throw std::invalid_argument(std::string("renderer: ") + what + ": material out of range");
  };
  check_mesh(scene.object_mesh, "object mesh");
  for (const auto& m : scene.scenery) check_mesh(m, "scenery mesh");
  for (const auto& m : scene.occluders) check_mesh(m, "occluder mesh");
  for (const auto& mat : scene.materials)
    if (mat.texture >= n_tex || (mat.texture >= 0 && scene.textures[static_cast<std::size_t>(mat.texture)].type() != CV_8UC3))
      throw std::invalid_argument("renderer: material texture missing or not 8-bit BGR");
  for (const auto& p : scene.background.planes) {
    const cv::Mat* t = p.texture >= 0 && p.texture < n_tex ? &scene.textures[static_cast<std::size_t>(p.texture)] : nullptr;
    if (p.texture >= n_tex || (t && (t->type() != CV_8UC3 || t->cols < 2 || t->rows < 2)))
      throw std::invalid_argument("renderer: environment texture missing, smaller than 2x2 or not 8-bit BGR");
  }
}

void Renderer::Impl::setup_ideal_camera() {
  const auto& k = camera.intrinsics();
  fx = k.fx_px; fy = k.fy_px; cx = k.cx_px; cy = k.cy_px;
  W = camera.width_px(); H = camera.height_px();
  distort = camera.has_distortion();
  if (!distort) return;
  // The ideal image covers the undistorted positions of the real image's border.
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  auto add = [&](double u, double v) {
    const Eigen::Vector2d xn = camera.pixel_to_normalized({u, v});
    if (!xn.allFinite()) return;
    xmin = std::min(xmin, fx * xn.x() + cx); xmax = std::max(xmax, fx * xn.x() + cx);
    ymin = std::min(ymin, fy * xn.y() + cy); ymax = std::max(ymax, fy * xn.y() + cy);
  };
  const int w = camera.width_px(), h = camera.height_px();
  for (int u = 0; u < w; ++u) { add(u - 0.5, -0.5); add(u - 0.5, h - 0.5); }
  for (int v = 0; v < h; ++v) { add(-0.5, v - 0.5); add(w - 0.5, v - 0.5); }
  add(w - 0.5, h - 0.5);
  // A wild distortion model must not make the buffers explode: at most 2x the image each way.
  xmin = std::max(xmin, -1.0 * w); xmax = std::min(xmax, 2.0 * w);
  ymin = std::max(ymin, -1.0 * h); ymax = std::min(ymax, 2.0 * h);
  const double x0 = std::floor(xmin) - 2, y0 = std::floor(ymin) - 2;
  W = static_cast<int>(std::ceil(xmax) + 3 - x0);
  H = static_cast<int>(std::ceil(ymax) + 3 - y0);
  cx -= x0; cy -= y0;
  cv::Mat mx(h, w, CV_32F), my(h, w, CV_32F);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const Eigen::Vector2d xn = camera.pixel_to_normalized({static_cast<double>(u), static_cast<double>(v)});
      mx.at<float>(v, u) = static_cast<float>(fx * xn.x() + cx);
      my.at<float>(v, u) = static_cast<float>(fy * xn.y() + cy);
    }
  cv::convertMaps(mx, my, map1, map2, CV_16SC2);
}

Renderer::Renderer(Scene scene, const vision::Camera& camera, const RenderOptions& options)
    : impl_(std::make_unique<Impl>(std::move(scene), camera, options)) {}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

void Renderer::render(const FrameInput& frame, cv::RNG& rng, cv::Mat& out_bgr) { impl_->render(frame, rng, out_bgr); }
cv::Mat Renderer::render(const FrameInput& frame, cv::RNG& rng) {
  cv::Mat out;
  impl_->render(frame, rng, out);
  return out;
}
const Scene& Renderer::scene() const { return impl_->scene; }
const vision::Camera& Renderer::camera() const { return impl_->camera; }
const RenderOptions& Renderer::options() const { return impl_->opt; }

}  // namespace epichead::sim
