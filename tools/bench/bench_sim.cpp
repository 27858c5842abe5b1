// Simulator benchmarks.
#include <memory>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "bench/bench.h"
#include "epichead/sim/renderer.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene_library.h"

namespace epichead::bench {
namespace {

// One box_clutter frame as `epichead sim box_clutter` renders it: the built-in scenario's blur
// sub-frames, exposure, anti-aliasing and noise, with a hand-held camera moving at 0.1 m/s and
// turning at 20 deg/s (a few pixels of blur).
struct RenderBox {
  std::unique_ptr<sim::Renderer> renderer;
  std::vector<sim::SubFrame> subs;
  sim::FrameInput input;
  cv::RNG rng{1};
  cv::Mat image;
};

const Registration render_box{"sim_render_box", [] {
  auto scenario = sim::find_scenario("box_clutter");
  if (!scenario) throw std::runtime_error(scenario.error());
  auto scene = sim::make_scene(scenario->scene);
  if (!scene) throw std::runtime_error(scene.error());
  sim::RenderOptions options;
  options.samples_per_subframe = scenario->antialias_samples;
  options.noise_sigma_dn = scenario->noise_dn;
  auto s = std::make_shared<RenderBox>();
  const vision::Camera camera(640, 480, {839.2, 839.4, 325.7, 243.7});
  const Eigen::Isometry3d world_T_cam = sim::look_at(scene->view.camera_world, scene->view.target_world);
  const int n = scenario->blur_subframes.value_or(scene->blur_subframes);
  const double exposure_s = scenario->exposure_s.value_or(scene->exposure_s);
  s->subs.resize(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double dt = exposure_s * ((k + 0.5) / n - 0.5);
    s->subs[static_cast<std::size_t>(k)].world_T_cam =
        world_T_cam * Eigen::Translation3d(0.1 * dt, 0, 0) * Eigen::AngleAxisd(0.35 * dt, Eigen::Vector3d::UnitY());
  }
  s->renderer = std::make_unique<sim::Renderer>(std::move(*scene), camera, options);
  s->input.sub_frames = s->subs;
  s->input.t_s = 1.0;
  return [s] { s->renderer->render(s->input, s->rng, s->image); };
}};

}  // namespace
}  // namespace epichead::bench
