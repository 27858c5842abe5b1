#pragma once
// Renders camera frames of a Scene through a calibrated camera (with its lens distortion):
// filled, Lambert-shaded, textured triangles with a z-buffer, anti-aliased, over the
// environment, with motion blur (average of sub-frame renders), cast shadows, a global light
// gain, gamma and Gaussian sensor noise. Deterministic: the same inputs and RNG state give the
// same bytes. Single-threaded. One Renderer holds its buffers, so rendering allocates nothing
// after the first frame (bench: sim_render_box).
#include <memory>
#include <span>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/sim/scene.h"
#include "epichead/vision/camera.h"

namespace epichead::sim {

struct RenderOptions {
  // Anti-aliasing samples per pixel in each sub-frame. The samples of all sub-frames of a frame
  // sit at distinct sub-pixel positions, so a frame with 4 sub-frames of 4 samples resolves an
  // edge to 1/16 pixel even when nothing moves.
  int samples_per_subframe = 4;
  double gamma = 2.2;          // output = 255 * radiance^(1/gamma); textures are decoded likewise
  double noise_sigma_dn = 1.5; // Gaussian noise added to the 8-bit output, in grey levels
  bool shadows = true;         // draw the scene's cast shadows when the scene enables them
  double near_m = 0.02;        // geometry closer to the camera than this is clipped
};

// The poses at one instant inside the exposure.
struct SubFrame {
  Eigen::Isometry3d world_T_cam = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_T_obj = Eigen::Isometry3d::Identity();  // the tracked object
  // One pose per Scene::occluders entry; occluders without a pose here are not drawn.
  std::span<const Eigen::Isometry3d> world_T_occluders;
};

struct FrameInput {
  double t_s = 0;                        // frame time: drives the time-varying reflectance
  // Sub-frame poses spread over the exposure, equally weighted (one = no motion blur). Ground
  // truth for the frame is the pose at the middle of the exposure. Objects are drawn at every
  // sub-frame; the environment behind them at as few instants (interpolated between sub-frames)
  // as keep its copies within 1.5 px of each other, so a still background is drawn once.
  std::span<const SubFrame> sub_frames;
  double illumination_gain = 1.0;        // global light level (1 = nominal): lighting drift
};

class Renderer {
 public:
  // Throws std::invalid_argument when the scene refers to a missing material or texture
  // (the scenes are built in code: that is a programming error).
  Renderer(Scene scene, const vision::Camera& camera, const RenderOptions& options = {});
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  // Renders one frame into `out_bgr` (8-bit BGR, camera size; reallocated only if needed).
  // Noise is drawn from `rng`. An empty sub_frames list renders nothing but the noise-free
  // plain background colour.
  void render(const FrameInput& frame, cv::RNG& rng, cv::Mat& out_bgr);
  cv::Mat render(const FrameInput& frame, cv::RNG& rng);

  const Scene& scene() const;
  const vision::Camera& camera() const;
  const RenderOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace epichead::sim
