// Simulator benchmarks.
#include <memory>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "bench/bench.h"
#include "epichead/sim/renderer.h"
#include "epichead/sim/scene_library.h"

namespace epichead::bench {
namespace {

// One box_clutter frame as a sequence renders it: the scene's blur sub-frames over its exposure,
// a hand-held camera moving at 0.1 m/s and turning at 20 deg/s (a few pixels of blur).
struct RenderBox {
  std::unique_ptr<sim::Renderer> renderer;
  std::vector<sim::SubFrame> subs;
  sim::FrameInput input;
  cv::RNG rng{1};
  cv::Mat image;
};

const Registration render_box{"sim_render_box", [] {
  auto scene = sim::make_scene("box_clutter");
  if (!scene) throw std::runtime_error(scene.error());
  auto s = std::make_shared<RenderBox>();
  const vision::Camera camera(640, 480, {839.2, 839.4, 325.7, 243.7});
  const Eigen::Isometry3d world_T_cam = sim::look_at(scene->view.camera_world, scene->view.target_world);
  const int n = scene->blur_subframes;
  const double exposure_s = scene->exposure_s;
  s->subs.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double dt = exposure_s * ((k + 0.5) / n - 0.5);
    s->subs[static_cast<std::size_t>(k)].world_T_cam =
        world_T_cam * Eigen::Translation3d(0.1 * dt, 0, 0) * Eigen::AngleAxisd(0.35 * dt, Eigen::Vector3d::UnitY());
  }
  s->renderer = std::make_unique<sim::Renderer>(std::move(*scene), camera);
  s->input.sub_frames = s->subs;
  s->input.t_s = 1.0;
  return [s] { s->renderer->render(s->input, s->rng, s->image); };
}};

}  // namespace
}  // namespace epichead::bench
