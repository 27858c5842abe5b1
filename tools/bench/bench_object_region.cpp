// Benchmark object_region_can: ObjectRegion::learn on the can scenario's first frame at its
// true pose (the model drawn, the distances to its outline in the drawn box, the two colour
// histograms). It runs on the frames that settle (the first, after a loss, per detection
// hypothesis), so what it adds to a detection is this times the hypotheses refined.
#include <memory>
#include <stdexcept>

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

const Registration object_region_can{"object_region_can", [] {
  auto b = std::make_shared<RegionBench>();
  b->sim = simulate_builtin("can", 1);
  (void)b->image.assign(b->sim.frames.front());
  const Eigen::Isometry3d pose = b->sim.seq->ground_truth().front().cam_T_obj;
  if (!b->region.learn(b->image, b->sim.seq->model(), b->sim.seq->camera(), pose))
    throw std::runtime_error("object_region_can: the can's region was not learnt");
  return [b, pose] { b->region.learn(b->image, b->sim.seq->model(), b->sim.seq->camera(), pose); };
}};

}  // namespace
}  // namespace epichead::bench
