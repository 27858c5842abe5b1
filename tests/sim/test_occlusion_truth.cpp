// The occlusion truth behind sim_truth.json's object_hidden_frames: while a cover board slides
// in and out, it says "hidden" exactly when the drawn frame shows nothing of the object (the
// frame rendered with and without the object is the same), and "not hidden" without occluders.
#include <catch2/catch.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/sim/occlusion_truth.h"
#include "epichead/sim/renderer.h"
#include "epichead/sim/rig.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/scene_variety.h"
#include "occluder_motion.h"

using namespace epichead::sim;

namespace {

// Pixels that differ by more than sensor-free rounding between two renders.
int differing_pixels(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff, grey;
  cv::absdiff(a, b, diff);
  cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
  return cv::countNonZero(grey > 2);
}

}  // namespace

TEST_CASE("the occlusion truth says hidden exactly when the drawn frame shows nothing of the object", "[sim][occlusion]") {
  auto builtin = find_scenario("can");
  REQUIRE(builtin);
  builtin->seed = 3;
  auto made = make_scenario_scene(*builtin);
  INFO((made ? "" : made.error()));
  REQUIRE(made);
  const Scenario& s = made->scenario;
  REQUIRE(s.covers.size() == 1);
  const CoverWindow cover = s.covers[0];
  const Rig rig = Rig::from_scenario(s, made->scene.view.target_world, made->scene.world_T_obj);
  OcclusionTruth truth(made->scene, s);

  // Noise-free, one sample, no shadows (the object's shadow is not the object): a render with
  // the object and one without differ exactly where the object is in sight.
  RenderOptions options;
  options.samples_per_subframe = 1;
  options.noise_sigma_dn = 0;
  options.shadows = false;
  Scene without_object = made->scene;
  without_object.object_mesh = {};
  const auto camera = default_camera();
  Renderer with(made->scene, camera, options), without(std::move(without_object), camera, options);

  std::vector<Eigen::Isometry3d> occluders;
  cv::RNG rng_a(1), rng_b(1);
  cv::Mat a, b;
  int hidden = 0, in_sight = 0;
  const double slide_s = CoverWindow::kSlideS;
  for (const double from_s : {cover.start_s - slide_s - 0.05, cover.start_s + cover.duration_s - 0.05}) {
    for (double t = from_s; t < from_s + slide_s + 0.1; t += 1.0 / 60) {
      const Eigen::Isometry3d world_T_cam = rig.world_T_cam(t).pose;
      occluder_poses_at(made->scene, s, t, occluders);
      const SubFrame sub{world_T_cam, made->scene.world_T_obj, occluders};
      const FrameInput frame{t, {&sub, 1}, 1.0};
      with.render(frame, rng_a, a);
      without.render(frame, rng_b, b);
      const int shown = differing_pixels(a, b);
      const bool says_hidden = truth.hides_object(t, world_T_cam);
      INFO("t " << t << " s: " << shown << " pixels of the object in sight; truth says " << (says_hidden ? "hidden" : "not hidden"));
      if (says_hidden) CHECK(shown == 0);
      else CHECK(shown > 0);
      (says_hidden ? hidden : in_sight) += 1;
    }
  }
  // Both answers occur while the board slides (the test saw the edge cross the object).
  CHECK(hidden >= 4);
  CHECK(in_sight >= 4);
}

TEST_CASE("the occlusion truth never says hidden without occluders", "[sim][occlusion]") {
  auto builtin = find_scenario("office_pan");
  REQUIRE(builtin);
  auto made = make_scenario_scene(*builtin);
  REQUIRE(made);
  Scene bare = made->scene;
  bare.occluders.clear();
  bare.occluder_paths.clear();
  Scenario keyless = made->scenario;
  keyless.occluder_keys.clear();
  OcclusionTruth truth(bare, keyless);
  const Rig rig = Rig::from_scenario(keyless, bare.view.target_world, bare.world_T_obj);
  for (double t = 0.2; t < 3; t += 0.5) CHECK_FALSE(truth.hides_object(t, rig.world_T_cam(t).pose));
}
