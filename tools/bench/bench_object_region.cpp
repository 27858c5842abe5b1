// ObjectRegion::learn (the model drawn, the distances to its outline, the two colour
// histograms) on a scenario's first frame at its true pose:
//   object_region_can   the can (cylinder and rims), small in the frame
//   object_region_box   box_clutter's printed package, 640x480: a box like the real tea box's
// It runs on the frames that settle (the first, after a loss, per detection hypothesis), so
// what it adds to a detection is this times the hypotheses refined.
#include <memory>
#include <stdexcept>
#include <string>

#include "bench/bench.h"
#include "bench/simulated_sequence.h"
#include "epichead/vision/object_region.h"
#include "epichead/vision/window_image.h"

namespace epichead::bench {
namespace {

struct RegionBench {
  SimulatedSequence sim;
  vision::WindowImage image;
  vision::ObjectRegion region;
};

Iteration learn_on(const std::string& scenario) {
  auto b = std::make_shared<RegionBench>();
  b->sim = simulate_builtin(scenario, 1);
  (void)b->image.assign(b->sim.frames.front());
  const Eigen::Isometry3d pose = b->sim.seq->ground_truth().front().cam_T_obj;
  if (!b->region.learn(b->image, b->sim.seq->model(), b->sim.seq->camera(), pose))
    throw std::runtime_error("object_region: the region of " + scenario + " was not learnt");
  return [b, pose] { b->region.learn(b->image, b->sim.seq->model(), b->sim.seq->camera(), pose); };
}

const Registration object_region_can{"object_region_can", [] { return learn_on("can"); }};
const Registration object_region_box{"object_region_box", [] { return learn_on("box_clutter"); }};

}  // namespace
}  // namespace epichead::bench
