// A start's frame: ModelTracker::reset() and the first track() from the true pose, with what
// only a start does (the outline colours, settle()'s measurements from the start pose and from
// a gradient pass's pose) besides the measurement every frame makes. What a detection's
// hypothesis or init.csv costs the frame it starts on; track_cycle is the frame after.
//   track_start_box   box_clutter's printed package, 640x480 (a box like the real tea box)
//   track_start_can   the can (ellipses, cylinder)
#include <memory>
#include <stdexcept>
#include <string>

#include "bench/bench.h"
#include "bench/simulated_sequence.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/window_image.h"

namespace epichead::bench {
namespace {

struct StartBench {
  std::unique_ptr<vision::Sequence> seq;
  vision::WindowImage image;
  std::unique_ptr<vision::ModelTracker> tracker;
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  vision::FrameReport report;
};

Iteration start_on(const std::string& scenario) {
  SimulatedSequence sim = simulate_builtin(scenario, 1);
  auto b = std::make_shared<StartBench>();
  b->seq = std::move(sim.seq);
  if (auto ok = b->image.assign(sim.frames.front()); !ok) throw std::runtime_error(ok.error());
  b->start = b->seq->ground_truth().front().cam_T_obj;
  b->tracker = std::make_unique<vision::ModelTracker>(b->seq->model(), b->seq->camera());
  return [b] {
    b->tracker->reset();
    b->tracker->track(b->image, b->start, b->report);
  };
}

const Registration track_start_box{"track_start_box", [] { return start_on("box_clutter"); }};
const Registration track_start_can{"track_start_can", [] { return start_on("can"); }};

}  // namespace
}  // namespace epichead::bench
