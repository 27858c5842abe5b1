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

#include "render_clip.h"
#include "render_environment.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <numeric>
#include <optional>
#include <cstring>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace epichead::sim {
namespace {

using render::ClipPlane;
using render::Vertex;
using render::clip_polygon;

constexpr int kFixShift = 8;                    // vertices snap to 1/256 px
constexpr std::int64_t kFixOne = std::int64_t{1} << kFixShift;
constexpr int kMaxSamplesPerSubframe = 16;
constexpr int kMaxSamplesPerFrame = 256;
constexpr double kEnvStepPx = 1.0;              // largest environment motion between its blur copies
constexpr int kTile = 64;                       // object tiles: 64 x 64 pixels

std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
std::int64_t ceil_div(std::int64_t a, std::int64_t b) {   // b > 0
  return a >= 0 ? (a + b - 1) / b : -((-a) / b);
}

// Per-frame material data: everything that varies with time folded in once.
struct FrameMaterial {
  Eigen::Vector3f albedo;
  float albedo_max = 1;
  float time_factor = 1;
  Eigen::Vector3f gradient = Eigen::Vector3f::Zero();
  Eigen::Vector3f gradient_origin = Eigen::Vector3f::Zero();
  int texture = -1;
  Eigen::Vector3f tex_origin = Eigen::Vector3f::Zero(), tex_u = Eigen::Vector3f::Zero(), tex_v = Eigen::Vector3f::Zero();
};

// A triangle ready for rasterisation in the ideal image.
struct RasterTriangle {
  std::int64_t X[3], Y[3];  // fixed-point vertices, positive orientation
  int bias[3];              // top-left rule: 0 for edges that own their samples, -1 otherwise
  int mip = 0;              // texture level
  int x0, y0, x1, y1;       // pixel bounding box, clamped to the image
  // Attribute planes a*(x - x0) + b*(y - y0) + c: 1/z, shade/z, u/z, v/z.
  float w[3], s[3], u[3], v[3];
  int material;
};

// A sample pattern for T samples: distinct x and y offsets (an axis-aligned edge gets T + 1 grey
// levels) spread over the pixel. Rank-1 lattice (s, s*p mod T); small T brute-force the best
// permutation (the rotated-grid pattern for T = 4).
std::vector<Eigen::Vector2i> make_pattern(int T) {
  std::vector<int> best_perm(static_cast<std::size_t>(T));
  for (int i = 0; i < T; ++i) best_perm[static_cast<std::size_t>(i)] = i;
  auto min_dist = [&](const std::vector<int>& perm) {
    double best = 1e9;
    for (int i = 0; i < T; ++i)
      for (int j = i + 1; j < T; ++j) {
        double dx = std::abs(i - j), dy = std::abs(perm[static_cast<std::size_t>(i)] - perm[static_cast<std::size_t>(j)]);
        dx = std::min(dx, T - dx);
        dy = std::min(dy, T - dy);
        best = std::min(best, dx * dx + dy * dy);
      }
    return best;
  };
  double best = -1;
  if (T <= 8) {
    std::vector<int> perm = best_perm;
    do {
      const double d = min_dist(perm);
      if (d > best) { best = d; best_perm = perm; }
    } while (std::next_permutation(perm.begin(), perm.end()));
  } else {
    for (int p = 1; p < T; ++p) {
      if (std::gcd(p, T) != 1) continue;
      std::vector<int> perm(static_cast<std::size_t>(T));
      for (int s = 0; s < T; ++s) perm[static_cast<std::size_t>(s)] = (s * p) % T;
      const double d = min_dist(perm);
      if (d > best) { best = d; best_perm = perm; }
    }
  }
  std::vector<Eigen::Vector2i> out;
  for (int s = 0; s < T; ++s) {
    // Offsets from the pixel centre in 1/256 px, in (-128, 128).
    const auto off = [&](int i) {
      return static_cast<int>(std::lround(((i + 0.5) / T - 0.5) * static_cast<double>(kFixOne)));
    };
    out.emplace_back(off(s), off(best_perm[static_cast<std::size_t>(s)]));
  }
  return out;
}

}  // namespace

struct Renderer::Impl {
  Scene scene;
  vision::Camera camera;
  RenderOptions opt;

  // Ideal (undistorted) pinhole image.
  int W = 0, H = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  bool distort = false;
  cv::Mat map1, map2;  // output pixel -> ideal pixel (fixed point)

  // Per scene texture: a mip pyramid of 8-bit BGRA (empty if no material uses it). Minified
  // textures are read from the level that matches the screen size: no sparkle, and the reads
  // stay in cache (why 8-bit: texel fetches dominate the object pass; 4 bytes a texel halve
  // its time against float). Filtering happens on the encoded values, decoding after.
  struct MipLevel {
    cv::Mat image;
    float su = 1, sv = 1;              // level texels per level-0 texel
    float inv_cols = 1, inv_rows = 1;  // 1 / size, for wrapping
  };
  std::vector<std::vector<MipLevel>> tex_mips;
  float decode_lut[256];
  static constexpr int kDecodeFine = 4;  // steps per grey level of the filtered-texel decode table
  float decode_fine[255 * kDecodeFine + 2];
  std::vector<float> encode_lut;    // linear [0, 1] -> 0..255, kEncodeSteps + 1 entries
  static constexpr int kEncodeSteps = 65536;
  std::vector<float> gauss_table;   // N(0, 1) quantiles of 65536 equal-probability bins

  int M = 1;  // samples per sub-frame
  // Objects are drawn tile by tile so that the sample buffers stay in cache.
  std::vector<float> depth;         // kTile^2 pixels of M samples: 1/z, 0 = empty
  std::vector<float> color;         // kTile^2 pixels of M samples of 3 channels
  std::vector<float> env_linear;    // W*H*3
  cv::Mat corr, encoded, remapped;  // CV_32FC3: object minus environment, gamma-encoded, distorted
  cv::Rect corr_box;                 // where corr holds this frame's values
  std::vector<RasterTriangle> tris;
  std::vector<FrameMaterial> materials;
  std::vector<std::vector<Eigen::Vector2i>> patterns;  // by total sample count
  render::ClipPlane clip_planes[5];
  std::optional<render::EnvironmentLayer> environment;
  std::vector<render::EnvironmentInstant> env_instants;

  Impl(Scene s, const vision::Camera& cam, const RenderOptions& o) : scene(std::move(s)), camera(cam), opt(o) {
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

  void validate() const {
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

  void setup_ideal_camera() {
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

  void setup_tables() {
    const double g = opt.gamma > 0 ? opt.gamma : 1.0;
    for (int i = 0; i < 256; ++i) decode_lut[i] = static_cast<float>(std::pow(i / 255.0, g));
    for (int i = 0; i <= 255 * kDecodeFine + 1; ++i)
      decode_fine[i] = static_cast<float>(std::pow(std::min(1.0, i / (255.0 * kDecodeFine)), g));
    encode_lut.resize(kEncodeSteps + 1);
    for (int i = 0; i <= kEncodeSteps; ++i)
      encode_lut[static_cast<std::size_t>(i)] = static_cast<float>(255.0 * std::pow(static_cast<double>(i) / kEncodeSteps, 1.0 / g));
    gauss_table.resize(65536);
    // Inverse normal CDF at bin centres (Acklam's rational approximation refined by one Newton
    // step on erfc), so a 16-bit uniform draw gives a Gaussian value.
    for (int i = 0; i < 65536; ++i) {
      const double p = (i + 0.5) / 65536.0;
      double x = inverse_normal(p);
      const double e = 0.5 * std::erfc(-x / std::numbers::sqrt2) - p;
      x -= e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
      gauss_table[static_cast<std::size_t>(i)] = static_cast<float>(x);
    }
  }

  static double inverse_normal(double p) {
    static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                               1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
    static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                               6.680131188771972e+01, -1.328068155288572e+01};
    static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                               -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
    static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                               3.754408661907416e+00};
    if (p < 0.02425) {
      const double q = std::sqrt(-2 * std::log(p));
      return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
             ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    }
    if (p > 1 - 0.02425) return -inverse_normal(1 - p);
    const double q = p - 0.5, r = q * q;
    return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
           (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }

  void setup_textures() {
    tex_mips.resize(scene.textures.size());
    for (const auto& mat : scene.materials) {
      if (mat.texture < 0) continue;
      auto& mips = tex_mips[static_cast<std::size_t>(mat.texture)];
      if (!mips.empty()) continue;
      const cv::Mat& t8 = scene.textures[static_cast<std::size_t>(mat.texture)];
      cv::Mat bgra;
      cv::cvtColor(t8, bgra, cv::COLOR_BGR2BGRA);
      mips.push_back({bgra, 1.f, 1.f, 1.f / static_cast<float>(bgra.cols), 1.f / static_cast<float>(bgra.rows)});
      while (mips.back().image.cols >= 8 && mips.back().image.rows >= 8 && mips.size() < 12) {
        cv::Mat half;
        cv::resize(mips.back().image, half, cv::Size(mips.back().image.cols / 2, mips.back().image.rows / 2), 0, 0,
                   cv::INTER_AREA);
        mips.push_back({half, static_cast<float>(half.cols) / static_cast<float>(t8.cols),
                        static_cast<float>(half.rows) / static_cast<float>(t8.rows), 1.f / static_cast<float>(half.cols),
                        1.f / static_cast<float>(half.rows)});
      }
    }
  }

  const std::vector<Eigen::Vector2i>& pattern(int total) {
    auto& p = patterns[static_cast<std::size_t>(total)];
    if (p.empty()) p = make_pattern(total);
    return p;
  }

  void update_materials(double t_s) {
    for (std::size_t i = 0; i < scene.materials.size(); ++i) {
      const Material& m = scene.materials[i];
      FrameMaterial& f = materials[i];
      const double s = m.change_period_s > 0 ? std::sin(2 * std::numbers::pi * t_s / m.change_period_s + m.change_phase_rad) : 0.0;
      f.albedo = m.albedo_bgr.cwiseMax(0.f).cwiseMin(1.f);
      f.albedo_max = std::max(f.albedo.maxCoeff(), 1e-3f);
      f.time_factor = static_cast<float>(std::max(0.0, 1 + m.change_amplitude * s));
      f.gradient = (m.gradient_per_m_obj * (1 + m.gradient_swing * s)).cast<float>();
      f.gradient_origin = m.gradient_origin_obj.cast<float>();
      f.texture = m.texture;
      f.tex_origin = m.tex_origin_obj.cast<float>();
      f.tex_u = (m.tex_u_obj * m.tex_px_per_m).cast<float>();
      f.tex_v = (m.tex_v_obj * m.tex_px_per_m).cast<float>();
    }
  }

  // ---- objects ----------------------------------------------------------------------------

  // Transforms, culls, lights, clips and sets up the triangles of one posed mesh.
  void add_mesh(const Mesh& mesh, const Eigen::Isometry3d& cam_T_mesh, const Eigen::Isometry3d& world_T_mesh) {
    const Eigen::Matrix3f R = cam_T_mesh.linear().cast<float>();
    const Eigen::Vector3f t = cam_T_mesh.translation().cast<float>();
    if (!R.allFinite() || !t.allFinite()) return;
    const Eigen::Vector3f light = (world_T_mesh.linear().transpose() * scene.light.direction_world.normalized()).cast<float>();
    const float ambient = static_cast<float>(scene.light.ambient), diffuse = static_cast<float>(scene.light.diffuse);
    // Camera centre in the mesh frame: back-facing test without transforming normals.
    const Eigen::Vector3f eye = -(R.transpose() * t);
    for (std::size_t ti = 0; ti < mesh.triangles.size(); ++ti) {
      const auto& tri = mesh.triangles[ti];
      const Eigen::Vector3f& p0 = mesh.positions[static_cast<std::size_t>(tri[0])];
      const Eigen::Vector3f& p1 = mesh.positions[static_cast<std::size_t>(tri[1])];
      const Eigen::Vector3f& p2 = mesh.positions[static_cast<std::size_t>(tri[2])];
      const Eigen::Vector3f n_geo = (p1 - p0).cross(p2 - p0);
      const bool front = n_geo.dot(eye - p0) > 0;
      if (!front && mesh.closed) continue;
      const int mat = mesh.triangle_material[ti];
      const FrameMaterial& fm = materials[static_cast<std::size_t>(mat)];
      Vertex v[3];
      for (int k = 0; k < 3; ++k) {
        const auto idx = static_cast<std::size_t>(tri[static_cast<std::size_t>(k)]);
        const Eigen::Vector3f& p = mesh.positions[idx];
        // The lit side of an open surface is the side the camera sees.
        const float ndotl = (front ? 1.f : -1.f) * mesh.normals[idx].dot(light);
        const float lighting = ambient + diffuse * std::max(0.f, ndotl);
        float reflect = fm.time_factor * std::max(0.f, 1 + fm.gradient.dot(p - fm.gradient_origin));
        reflect = std::min(reflect, 1.f / fm.albedo_max);
        v[k].p = R * p + t;
        v[k].shade = lighting * reflect;
        if (fm.texture >= 0) {
          v[k].u = fm.tex_u.dot(p - fm.tex_origin) - 0.5f;
          v[k].v = fm.tex_v.dot(p - fm.tex_origin) - 0.5f;
        }
      }
      if (!(v[0].p.allFinite() && v[1].p.allFinite() && v[2].p.allFinite())) continue;
      add_clipped(v, mat);
    }
  }

  void add_clipped(const Vertex (&v)[3], int mat) {
    // Fast path: the triangle is inside every clip plane.
    bool inside = true;
    for (const auto& plane : clip_planes)
      for (const auto& vert : v) inside = inside && plane.eval(vert.p) >= 0;
    if (inside) { add_projected(v[0], v[1], v[2], mat); return; }
    Vertex a[8], b[8];
    int n = 3;
    std::copy(v, v + 3, a);
    Vertex* in = a;
    Vertex* out = b;
    for (const auto& plane : clip_planes) {
      n = clip_polygon(in, n, plane, out);
      if (n < 3) return;
      std::swap(in, out);
    }
    for (int i = 1; i + 1 < n; ++i) add_projected(in[0], in[i], in[i + 1], mat);
  }

  void add_projected(const Vertex& a, const Vertex& b, const Vertex& c, int mat) {
    const Vertex* vs[3] = {&a, &b, &c};
    RasterTriangle t{};
    double w[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3f& p = vs[k]->p;
      w[k] = 1.0 / p.z();
      t.X[k] = std::llround((fx * p.x() * w[k] + cx) * kFixOne);
      t.Y[k] = std::llround((fy * p.y() * w[k] + cy) * kFixOne);
    }
    std::int64_t area = (t.X[1] - t.X[0]) * (t.Y[2] - t.Y[0]) - (t.Y[1] - t.Y[0]) * (t.X[2] - t.X[0]);
    if (area == 0) return;
    int order[3] = {0, 1, 2};
    if (area < 0) { std::swap(order[1], order[2]); area = -area; }
    RasterTriangle r{};
    for (int k = 0; k < 3; ++k) { r.X[k] = t.X[order[k]]; r.Y[k] = t.Y[order[k]]; }
    const std::int64_t min_x = std::min({r.X[0], r.X[1], r.X[2]}), max_x = std::max({r.X[0], r.X[1], r.X[2]});
    const std::int64_t min_y = std::min({r.Y[0], r.Y[1], r.Y[2]}), max_y = std::max({r.Y[0], r.Y[1], r.Y[2]});
    r.x0 = static_cast<int>(std::max<std::int64_t>(0, floor_div(min_x, kFixOne) - 1));
    r.y0 = static_cast<int>(std::max<std::int64_t>(0, floor_div(min_y, kFixOne) - 1));
    r.x1 = static_cast<int>(std::min<std::int64_t>(W - 1, ceil_div(max_x, kFixOne) + 1));
    r.y1 = static_cast<int>(std::min<std::int64_t>(H - 1, ceil_div(max_y, kFixOne) + 1));
    if (r.x0 > r.x1 || r.y0 > r.y1) return;
    for (int i = 0; i < 3; ++i) {
      const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
      const std::int64_t dx = r.X[a2] - r.X[a1], dy = r.Y[a2] - r.Y[a1];
      r.bias[i] = (dy > 0 || (dy == 0 && dx < 0)) ? 0 : -1;
    }
    // Attribute planes from the barycentric planes, in pixel units relative to (x0, y0).
    // (Snapped vertices, so that the planes agree with the coverage test.)
    const double A = static_cast<double>(area) / static_cast<double>(kFixOne * kFixOne);
    double lx[3], ly[3], l0[3];
    for (int i = 0; i < 3; ++i) {
      const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
      const double x1 = static_cast<double>(r.X[a1]) / kFixOne, y1 = static_cast<double>(r.Y[a1]) / kFixOne;
      const double x2 = static_cast<double>(r.X[a2]) / kFixOne, y2 = static_cast<double>(r.Y[a2]) / kFixOne;
      lx[i] = -(y2 - y1) / A;
      ly[i] = (x2 - x1) / A;
      l0[i] = ((x2 - x1) * (r.y0 - y1) - (y2 - y1) * (r.x0 - x1)) / A;
    }
    auto plane = [&](const double (&val)[3], float (&out)[3]) {
      double a = 0, b = 0, c = 0;
      for (int i = 0; i < 3; ++i) {
        a += lx[i] * val[order[i]];
        b += ly[i] * val[order[i]];
        c += l0[i] * val[order[i]];
      }
      out[0] = static_cast<float>(a); out[1] = static_cast<float>(b); out[2] = static_cast<float>(c);
    };
    double sw[3], uw[3], vw[3];
    for (int k = 0; k < 3; ++k) {
      sw[k] = vs[k]->shade * w[k];
      uw[k] = vs[k]->u * w[k];
      vw[k] = vs[k]->v * w[k];
    }
    plane(w, r.w);
    plane(sw, r.s);
    plane(uw, r.u);
    plane(vw, r.v);
    r.material = mat;
    const FrameMaterial& fm = materials[static_cast<std::size_t>(mat)];
    if (fm.texture >= 0) {
      // Level from texels per pixel over the whole triangle: log4 of the area ratio.
      const double uv_area = std::abs((b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u));
      const double px_area = A;
      const int levels = static_cast<int>(tex_mips[static_cast<std::size_t>(fm.texture)].size());
      const double ratio = uv_area / std::max(px_area, 1e-12);
      r.mip = ratio > 1 ? std::min(levels - 1, static_cast<int>(0.5 * std::log2(ratio))) : 0;
    }
    tris.push_back(r);
  }

  // Rasterises one triangle at the M sample positions of this sub-frame. Coverage and depth are
  // per sample (exact edges); the colour is evaluated once per pixel at the centroid of the
  // samples the triangle wins (multisampling: texture lookups dominate otherwise).
  void rasterise(const RasterTriangle& t, const Eigen::Vector2i* offsets, const cv::Rect& tile) {
    const FrameMaterial& fm = materials[static_cast<std::size_t>(t.material)];
    const MipLevel* tex = fm.texture >= 0 ? &tex_mips[static_cast<std::size_t>(fm.texture)][static_cast<std::size_t>(t.mip)] : nullptr;
    float ox[kMaxSamplesPerSubframe], oy[kMaxSamplesPerSubframe];
    float dw[kMaxSamplesPerSubframe];  // 1/z at a sample minus 1/z at the pixel centre
    for (int k = 0; k < M; ++k) {
      ox[k] = static_cast<float>(offsets[k].x()) / kFixOne;
      oy[k] = static_cast<float>(offsets[k].y()) / kFixOne;
      dw[k] = t.w[0] * ox[k] + t.w[1] * oy[k];
    }
    std::int64_t ex[3];  // edge function step per pixel in x
    for (int i = 0; i < 3; ++i) ex[i] = -(t.Y[(i + 2) % 3] - t.Y[(i + 1) % 3]) * kFixOne;
    std::int64_t lo[kMaxSamplesPerSubframe], hi[kMaxSamplesPerSubframe];
    // The tile, relative to the triangle's box.
    const std::int64_t tile_lo = std::max(0, tile.x - t.x0), tile_hi = std::min(t.x1, tile.x + tile.width - 1) - t.x0;
    const int y_end = std::min(t.y1, tile.y + tile.height - 1);
    for (int y = std::max(t.y0, tile.y); y <= y_end; ++y) {
      // Per sample: the span of this row where all three edge functions are >= 0 (exact).
      std::int64_t span_lo = tile_hi + 1, span_hi = -1;
      for (int k = 0; k < M; ++k) {
        const std::int64_t sx0 = static_cast<std::int64_t>(t.x0) * kFixOne + offsets[k].x();
        const std::int64_t sy = static_cast<std::int64_t>(y) * kFixOne + offsets[k].y();
        lo[k] = tile_lo;
        hi[k] = tile_hi;
        for (int i = 0; i < 3 && lo[k] <= hi[k]; ++i) {
          const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
          const std::int64_t e0 =
              (t.X[a2] - t.X[a1]) * (sy - t.Y[a1]) - (t.Y[a2] - t.Y[a1]) * (sx0 - t.X[a1]) + t.bias[i];
          if (ex[i] > 0) lo[k] = std::max(lo[k], ceil_div(-e0, ex[i]));
          else if (ex[i] < 0) hi[k] = std::min(hi[k], floor_div(e0, -ex[i]));
          else if (e0 < 0) hi[k] = -1;
        }
        if (lo[k] <= hi[k]) {
          span_lo = std::min(span_lo, lo[k]);
          span_hi = std::max(span_hi, hi[k]);
        }
      }
      if (span_lo > span_hi) continue;
      const float fy = static_cast<float>(y - t.y0);
      const float w_row = t.w[1] * fy + t.w[2];
      // Index in the tile buffers of the pixel at xi = 0.
      const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y - tile.y) * kTile + (t.x0 - tile.x);
      for (std::int64_t xi = span_lo; xi <= span_hi; ++xi) {
        const auto idx = static_cast<std::size_t>(row + xi);
        const float fxp = static_cast<float>(xi);
        unsigned won = 0;
        float cx_sum = 0, cy_sum = 0;
        for (int k = 0; k < M; ++k) {
          if (xi < lo[k] || xi > hi[k]) continue;
          const float w = t.w[0] * fxp + w_row + dw[k];
          float& d = depth[idx * static_cast<std::size_t>(M) + static_cast<std::size_t>(k)];
          if (!(w > d)) continue;
          d = w;
          won |= 1u << k;
          cx_sum += ox[k];
          cy_sum += oy[k];
        }
        if (!won) continue;
        const float n_won = static_cast<float>(std::popcount(won));
        const float px = fxp + cx_sum / n_won, py = fy + cy_sum / n_won;
        const float inv = 1.f / (t.w[0] * px + t.w[1] * py + t.w[2]);
        const float shade = (t.s[0] * px + t.s[1] * py + t.s[2]) * inv;
        float c0 = fm.albedo[0] * shade, c1 = fm.albedo[1] * shade, c2 = fm.albedo[2] * shade;
        if (tex) {
          const float u = (t.u[0] * px + t.u[1] * py + t.u[2]) * inv, v = (t.v[0] * px + t.v[1] * py + t.v[2]) * inv;
          const cv::Vec3f texel = sample_texture(*tex, (u + 0.5f) * tex->su - 0.5f, (v + 0.5f) * tex->sv - 0.5f, decode_fine);
          c0 *= texel[0]; c1 *= texel[1]; c2 *= texel[2];
        }
        for (int k = 0; k < M; ++k) {
          if (!(won & (1u << k))) continue;
          float* out = color.data() + 3 * (idx * static_cast<std::size_t>(M) + static_cast<std::size_t>(k));
          out[0] = c0; out[1] = c1; out[2] = c2;
        }
      }
    }
  }

  // Bilinear, repeating; returns linear factors.
  static cv::Vec3f sample_texture(const MipLevel& level, float u, float v, const float* decode) {
    const cv::Mat& tex = level.image;
    const float fw = static_cast<float>(tex.cols), fh = static_cast<float>(tex.rows);
    // Wrap only when outside: most faces map into their texture without repeating.
    if (!(u >= 0 && u < fw - 1)) u -= fw * std::floor(u * level.inv_cols);
    if (!(v >= 0 && v < fh - 1)) v -= fh * std::floor(v * level.inv_rows);
    int iu = static_cast<int>(u), iv = static_cast<int>(v);
    const float au = u - static_cast<float>(iu), av = v - static_cast<float>(iv);
    iu = std::clamp(iu, 0, tex.cols - 1);
    iv = std::clamp(iv, 0, tex.rows - 1);
    const int iu1 = iu + 1 == tex.cols ? 0 : iu + 1, iv1 = iv + 1 == tex.rows ? 0 : iv + 1;
    const uchar* r0 = tex.ptr<uchar>(iv);
    const uchar* r1 = tex.ptr<uchar>(iv1);
    const uchar *p00 = r0 + 4 * iu, *p01 = r0 + 4 * iu1, *p10 = r1 + 4 * iu, *p11 = r1 + 4 * iu1;
    const float w00 = (1 - au) * (1 - av) * kDecodeFine, w01 = au * (1 - av) * kDecodeFine;
    const float w10 = (1 - au) * av * kDecodeFine, w11 = au * av * kDecodeFine;
    cv::Vec3f out;
#if defined(__SSE4_1__)
    // All channels of a texel at once; the same operations in the same order as the scalar code.
    auto texel = [](const uchar* p) {
      std::int32_t bgra = 0;
      std::memcpy(&bgra, p, 4);
      return _mm_cvtepi32_ps(_mm_cvtepu8_epi32(_mm_cvtsi32_si128(bgra)));
    };
    __m128 e = _mm_mul_ps(_mm_set1_ps(w00), texel(p00));
    e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w01), texel(p01)));
    e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w10), texel(p10)));
    e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w11), texel(p11)));
    alignas(16) std::int32_t idx[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(idx), _mm_cvttps_epi32(_mm_add_ps(e, _mm_set1_ps(0.5f))));
    for (int ch = 0; ch < 3; ++ch) out[ch] = decode[idx[ch]];
#else
    for (int ch = 0; ch < 3; ++ch) {
      const float e = w00 * p00[ch] + w01 * p01[ch] + w10 * p10[ch] + w11 * p11[ch];
      out[ch] = decode[static_cast<int>(e + 0.5f)];
    }
#endif
    return out;
  }

  // ---- frame --------------------------------------------------------------------------------

  // Objects at one sub-frame: their samples replace the environment, added to `corr` as
  // (sample - environment) * weight, so that the environment itself is drawn once per frame.
  void object_pass(const SubFrame& sf, int sub_index, int n_sub, float weight) {
    const Eigen::Isometry3d cam_T_world = sf.world_T_cam.inverse();
    tris.clear();
    add_mesh(scene.object_mesh, cam_T_world * sf.world_T_obj, sf.world_T_obj);
    for (const auto& m : scene.scenery) add_mesh(m, cam_T_world, Eigen::Isometry3d::Identity());
    for (std::size_t i = 0; i < scene.occluders.size() && i < sf.world_T_occluders.size(); ++i)
      add_mesh(scene.occluders[i], cam_T_world * sf.world_T_occluders[i], sf.world_T_occluders[i]);
    int bx0 = W, by0 = H, bx1 = -1, by1 = -1;
    for (const auto& t : tris) {
      bx0 = std::min(bx0, t.x0); by0 = std::min(by0, t.y0);
      bx1 = std::max(bx1, t.x1); by1 = std::max(by1, t.y1);
    }
    if (bx1 < bx0) return;
    const auto& pat = pattern(std::min(n_sub * M, kMaxSamplesPerFrame));
    const int total = static_cast<int>(pat.size());
    Eigen::Vector2i offsets[kMaxSamplesPerSubframe];
    for (int k = 0; k < M; ++k) offsets[k] = pat[static_cast<std::size_t>((sub_index + n_sub * k) % total)];
    const cv::Rect box(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1);
    // Grow the corrected area, zeroing what is new to it.
    const cv::Rect grown = corr_box.area() > 0 ? (corr_box | box) : box;
    for (int y = grown.y; y < grown.y + grown.height; ++y) {
      float* c = corr.ptr<float>(y);
      for (int x = grown.x; x < grown.x + grown.width; ++x)
        if (!corr_box.contains({x, y})) c[3 * x] = c[3 * x + 1] = c[3 * x + 2] = 0.f;
    }
    corr_box = grown;
    for (int ty = by0; ty <= by1; ty += kTile)
      for (int tx = bx0; tx <= bx1; tx += kTile) {
        const cv::Rect tile(tx, ty, std::min(kTile, bx1 + 1 - tx), std::min(kTile, by1 + 1 - ty));
        bool any = false;
        for (const auto& t : tris) {
          if (t.x1 < tile.x || t.x0 >= tile.x + tile.width || t.y1 < tile.y || t.y0 >= tile.y + tile.height) continue;
          if (!any) std::fill(depth.begin(), depth.end(), 0.f);
          any = true;
          rasterise(t, offsets, tile);
        }
        if (any) resolve(tile, weight / static_cast<float>(M));
      }
  }

  // Adds each pixel's samples minus the environment behind them into `corr`.
  [[gnu::noinline]] void resolve(const cv::Rect& tile, float weight) {
    for (int y = tile.y; y < tile.y + tile.height; ++y) {
      float* c = corr.ptr<float>(y);
      const float* env = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
      for (int x = tile.x; x < tile.x + tile.width; ++x) {
        const std::size_t idx = static_cast<std::size_t>((y - tile.y) * kTile + (x - tile.x)) * static_cast<std::size_t>(M);
        float s0 = 0, s1 = 0, s2 = 0;
        int hits = 0;
        for (int k = 0; k < M; ++k) {
          if (!(depth[idx + static_cast<std::size_t>(k)] > 0)) continue;
          const float* col = color.data() + 3 * (idx + static_cast<std::size_t>(k));
          s0 += col[0]; s1 += col[1]; s2 += col[2];
          ++hits;
        }
        if (!hits) continue;
        const float h = static_cast<float>(hits);
        c[3 * x] += weight * (s0 - h * env[3 * x]);
        c[3 * x + 1] += weight * (s1 - h * env[3 * x + 1]);
        c[3 * x + 2] += weight * (s2 - h * env[3 * x + 2]);
      }
    }
  }

  // How far (ideal pixels) the environment moves in the image over the exposure: rays through
  // a 3x3 grid of the first sub-frame hit the environment (or a point 10 m away), and those
  // points are projected in the other sub-frames.
  double environment_motion_px(std::span<const SubFrame> subs) const {
    const Eigen::Isometry3d& first = subs.front().world_T_cam;
    double motion = 0;
    for (int gy = 0; gy < 3; ++gy)
      for (int gx = 0; gx < 3; ++gx) {
        const double u = (0.1 + 0.4 * gx) * W, v = (0.1 + 0.4 * gy) * H;
        const Eigen::Vector3d ray_world = first.linear() * Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1).normalized();
        double depth_m = 10;
        for (const auto& p : scene.background.planes) {
          const Eigen::Vector3d n = p.world_T_plane.linear().col(2);
          const double denom = n.dot(ray_world);
          if (std::abs(denom) < 1e-9) continue;
          const double d = n.dot(p.world_T_plane.translation() - first.translation()) / denom;
          if (d > 0) depth_m = std::min(depth_m, d);
        }
        const Eigen::Vector3d point = first.translation() + depth_m * ray_world;
        for (const auto& sf : subs.subspan(1)) {
          const Eigen::Vector3d p_cam = sf.world_T_cam.inverse() * point;
          if (p_cam.z() <= 1e-6) return 1e9;
          const double du = fx * p_cam.x() / p_cam.z() + cx - u, dv = fy * p_cam.y() / p_cam.z() + cy - v;
          motion = std::max(motion, std::hypot(du, dv));
        }
      }
    return std::isfinite(motion) ? motion : 1e9;
  }

  // Pose at fraction f (0..1) of the sub-frame sequence, interpolating neighbours.
  static Eigen::Isometry3d interpolate(std::span<const SubFrame> subs, double f, Eigen::Isometry3d SubFrame::*member) {
    const double s = f * static_cast<double>(subs.size() - 1);
    const std::size_t i = std::min(static_cast<std::size_t>(s), subs.size() - 1);
    const std::size_t j = std::min(i + 1, subs.size() - 1);
    const double a = s - static_cast<double>(i);
    const Eigen::Isometry3d& A = subs[i].*member;
    const Eigen::Isometry3d& B = subs[j].*member;
    Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
    out.linear() = Eigen::Quaterniond(A.linear()).slerp(a, Eigen::Quaterniond(B.linear())).toRotationMatrix();
    out.translation() = (1 - a) * A.translation() + a * B.translation();
    return out;
  }

  void render(const FrameInput& frame, cv::RNG& rng, cv::Mat& out) {
    out.create(camera.height_px(), camera.width_px(), CV_8UC3);
    const int n_sub = static_cast<int>(frame.sub_frames.size());
    if (n_sub == 0) {
      const cv::Vec3b plain = environment->plain_bgr8();
      out.setTo(cv::Scalar(plain[0], plain[1], plain[2]));
      return;
    }
    update_materials(frame.t_s);
    // The environment is drawn at as many instants as its own motion needs (at most one per
    // sub-frame): consecutive copies at most kEnvStepPx apart blur as smoothly as the bilinear
    // texture lookup can show, and a still background is drawn once.
    const auto subs = frame.sub_frames;
    const double motion = n_sub > 1 ? environment_motion_px(subs) : 0.0;
    const int n_env = std::clamp(1 + static_cast<int>(std::ceil(motion / kEnvStepPx)), 1, n_sub);
    env_instants.resize(static_cast<std::size_t>(n_env));
    for (int j = 0; j < n_env; ++j) {
      const double f = n_env == 1 ? 0.5 : static_cast<double>(j) / (n_env - 1);
      env_instants[static_cast<std::size_t>(j)] = {interpolate(subs, f, &SubFrame::world_T_cam),
                                                   interpolate(subs, f, &SubFrame::world_T_obj)};
    }
    environment->render(env_instants, opt.shadows && scene.shadows.enabled, env_linear.data());
    corr_box = cv::Rect();
    for (int i = 0; i < n_sub; ++i)
      object_pass(subs[static_cast<std::size_t>(i)], i, n_sub, 1.f / static_cast<float>(n_sub));

    // Gain and gamma through a table (pow per pixel would dominate the frame time).
    const float gain = static_cast<float>(std::max(0.0, frame.illumination_gain)) * kEncodeSteps;
    if (corr_box.area() > 0) {
      for (int y = corr_box.y; y < corr_box.y + corr_box.height; ++y) {
        float* a = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
        const float* c = corr.ptr<float>(y);
        for (int i = 3 * corr_box.x; i < 3 * (corr_box.x + corr_box.width); ++i) a[i] += c[i];
      }
    }
    auto encode_row = [&](int y, float* e) {
      const float* a = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
      for (int i = 0; i < 3 * W; ++i) {
        const float f = std::clamp(a[i] * gain, 0.f, static_cast<float>(kEncodeSteps) - 0.01f);
        const int j = std::min(static_cast<int>(f), kEncodeSteps - 1);
        const float r = f - static_cast<float>(j);
        e[i] = encode_lut[static_cast<std::size_t>(j)] * (1 - r) + encode_lut[static_cast<std::size_t>(j) + 1] * r;
      }
    };
    // Noise: a xorshift stream seeded from `rng`, mapped through the Gaussian quantile table.
    std::uint64_t state = (static_cast<std::uint64_t>(static_cast<unsigned>(rng)) << 32) | static_cast<unsigned>(rng);
    state |= 1;
    const float sigma = static_cast<float>(std::max(0.0, opt.noise_sigma_dn));
    auto noise_row = [&](const float* src, uchar* dst, int n) {
      for (int i = 0; i < n; ++i) {
        float val = src[i];
        if (sigma > 0) {
          state ^= state >> 12; state ^= state << 25; state ^= state >> 27;
          const std::uint64_t r = state * 0x2545F4914F6CDD1DULL;
          val += sigma * gauss_table[static_cast<std::size_t>(r >> 48)];
        }
        dst[i] = cv::saturate_cast<uchar>(val);
      }
    };
    if (!distort) {  // one pass, row by row
      for (int y = 0; y < H; ++y) {
        float* e = encoded.ptr<float>(0);
        encode_row(y, e);
        noise_row(e, out.ptr<uchar>(y), 3 * W);
      }
      return;
    }
    for (int y = 0; y < H; ++y) encode_row(y, encoded.ptr<float>(y));
    cv::remap(encoded, remapped, map1, map2, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    for (int y = 0; y < out.rows; ++y) noise_row(remapped.ptr<float>(y), out.ptr<uchar>(y), 3 * out.cols);
  }
};

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
