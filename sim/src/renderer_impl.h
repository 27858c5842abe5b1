#pragma once
// Private to the renderer: its state (Renderer::Impl) and the object pass's data, shared by the
// files that implement it in the order a frame uses them: renderer.cpp (set-up and checks),
// render_tables.cpp (lookup tables, sample patterns, texture mips), render_frame.cpp (one frame:
// environment, object passes, gain, gamma, distortion, noise), render_triangles.cpp (triangle
// set-up) and render_objects.cpp (rasterisation and resolve).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/sim/renderer.h"
#include "render_clip.h"
#include "render_environment.h"

namespace epichead::sim {
namespace render {

constexpr int kFixShift = 8;                    // vertices snap to 1/256 px
constexpr std::int64_t kFixOne = std::int64_t{1} << kFixShift;
constexpr int kMaxSamplesPerSubframe = 16;
constexpr int kMaxSamplesPerFrame = 256;
constexpr double kEnvStepPx = 1.0;              // largest environment motion between its blur copies
constexpr int kTile = 64;                       // object tiles: 64 x 64 pixels
constexpr int kDecodeFine = 4;                  // steps per grey level of the filtered-texel decode table
constexpr int kEncodeSteps = 65536;             // steps of the linear -> 8-bit encode table

inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {  // b > 0
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}
inline std::int64_t ceil_div(std::int64_t a, std::int64_t b) {   // b > 0
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

// One level of a texture's mip pyramid (see Renderer::Impl::tex_mips).
struct MipLevel {
  cv::Mat image;
  float su = 1, sv = 1;              // level texels per level-0 texel
  float inv_cols = 1, inv_rows = 1;  // 1 / size, for wrapping
};

}  // namespace render

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
  std::vector<std::vector<render::MipLevel>> tex_mips;
  float decode_lut[256];
  float decode_fine[255 * render::kDecodeFine + 2];
  std::vector<float> encode_lut;    // linear [0, 1] -> 0..255, kEncodeSteps + 1 entries
  std::vector<float> gauss_table;   // N(0, 1) quantiles of 65536 equal-probability bins

  int M = 1;  // samples per sub-frame
  // Objects are drawn tile by tile so that the sample buffers stay in cache.
  std::vector<float> depth;         // kTile^2 pixels of M samples: 1/z, 0 = empty
  std::vector<float> color;         // kTile^2 pixels of M samples of 3 channels
  std::vector<float> env_linear;    // W*H*3
  cv::Mat corr, encoded, remapped;  // CV_32FC3: object minus environment, gamma-encoded, distorted
  cv::Rect corr_box;                 // where corr holds this frame's values
  std::vector<render::RasterTriangle> tris;
  std::vector<render::FrameMaterial> materials;
  std::vector<std::vector<Eigen::Vector2i>> patterns;  // by total sample count
  render::ClipPlane clip_planes[5];
  std::optional<render::EnvironmentLayer> environment;
  std::vector<render::EnvironmentInstant> env_instants;

  // renderer.cpp: set-up.
  Impl(Scene s, const vision::Camera& cam, const RenderOptions& o);
  void validate() const;
  void setup_ideal_camera();

  // render_tables.cpp: tables built once.
  void setup_tables();
  void setup_textures();
  const std::vector<Eigen::Vector2i>& pattern(int total);

  // render_frame.cpp: one frame.
  void render(const FrameInput& frame, cv::RNG& rng, cv::Mat& out);
  void update_materials(double t_s);
  double environment_motion_px(std::span<const SubFrame> subs) const;

  // render_triangles.cpp: transform, cull, light, clip, project, set up.
  void add_mesh(const Mesh& mesh, const Eigen::Isometry3d& cam_T_mesh, const Eigen::Isometry3d& world_T_mesh);
  void add_clipped(const render::Vertex (&v)[3], int mat);
  void add_projected(const render::Vertex& a, const render::Vertex& b, const render::Vertex& c, int mat);

  // render_objects.cpp: the objects at one sub-frame.
  void object_pass(const SubFrame& sf, int sub_index, int n_sub, float weight);
  void rasterise(const render::RasterTriangle& t, const Eigen::Vector2i* offsets, const cv::Rect& tile);
  [[gnu::noinline]] void resolve(const cv::Rect& tile, float weight);
};

}  // namespace epichead::sim
