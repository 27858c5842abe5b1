#pragma once
// Private to the renderer: the environment behind the objects (textured planes: photos on far
// walls, the floor) with the objects' cast shadows on it, in linear light, averaged over the
// instants of the exposure at which it is drawn (its share of the motion blur).
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/sim/scene.h"
#include "render_clip.h"

namespace epichead::sim::render {

// The poses at one instant at which the environment is drawn (the object casts the shadow).
struct EnvironmentInstant {
  Eigen::Isometry3d world_T_cam = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_T_obj = Eigen::Isometry3d::Identity();
};

class EnvironmentLayer {
 public:
  // `scene` must outlive the layer (the renderer owns both). `decode_lut` maps 8-bit encoded
  // values to linear light with `gamma`.
  EnvironmentLayer(const Scene& scene, const IdealView& view, double gamma, const float (&decode_lut)[256]);

  // Writes the environment averaged over `instants` (equal weights; at least one) into `linear`
  // (view.W * view.H * 3 floats, BGR rows), shadows included when `shadows`. Allocates only when
  // a frame has more instants than any frame before.
  void render(std::span<const EnvironmentInstant> instants, bool shadows, float* linear);

  // The plain background colour, 8-bit encoded.
  cv::Vec3b plain_bgr8() const { return plain8_.back(); }

 private:
  // One environment plane as seen at one instant.
  struct PlaneView {
    bool visible = false;
    ScreenPolygon poly;
    Eigen::Matrix3d tex_from_px = Eigen::Matrix3d::Zero();  // ideal pixel -> texel (homogeneous)
  };
  // Shadows at one instant: a mask (0 lit .. 255 shadowed) and where it is non-zero.
  struct ShadowView {
    cv::Mat mask;
    cv::Rect box;
  };

  void setup_textures(double gamma);
  void prepare_instant(const EnvironmentInstant& instant, bool shadows, PlaneView* planes, ShadowView& shadow);
  void add_shadow(const Mesh& mesh, const Eigen::Isometry3d& world_T_mesh, const Eigen::Isometry3d& cam_T_world,
                  cv::Mat& mask, cv::Rect& box);
  void soften(cv::Mat& mask, const cv::Rect& r, double sigma_px);
  // Draws row y of one instant into row_ (and, when `receivers`, which pixels take shadows
  // into receiver_row_).
  void draw_row(const PlaneView* planes, int y, bool receivers);
  void warp_row(const PlaneView& pv, const cv::Mat& tex, int y, int x0, int x1, std::uint32_t* dst);

  const Scene* scene_;
  IdealView view_;
  float decode_lut_[256];
  float keep_ = 1;                     // share of the light a shadowed receiver keeps
  std::vector<cv::Mat> tex8_;          // per plane: tinted 8-bit BGRA texture (empty: plain)
  std::vector<cv::Vec3b> plain8_;      // per plane: plain colour; last entry: the background
  std::vector<PlaneView> plane_views_; // instant-major: instants x planes
  std::vector<ShadowView> shadows_;    // per instant
  cv::Mat blur_tmp_;                   // soften's intermediate
  std::vector<std::int32_t> col_sums_;
  std::vector<std::uint32_t> row_;     // one row of one instant, 8-bit BGR + 1 unused byte a pixel
  std::vector<std::uint8_t> receiver_row_;
  // Along a row: byte offset of the top-left texel, and the bilinear weights in 1/256.
  std::vector<std::int32_t> texel_offset_, frac_u_, frac_v_;
};

}  // namespace epichead::sim::render
