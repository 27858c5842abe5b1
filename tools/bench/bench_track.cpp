// The full tracking cycle (visibility, EPIC windows, validation, pose, reference update) on a
// short built-in mockup_walk sequence (25+ visible lines), one frame per iteration.
//   track_cycle        the tracking step alone, on window images made before the clock (their
//                      tiles converted by the first round, so later rounds convert none);
//   track_frame        what a frame costs the vision thread: the frame taken into the window
//                      image, then the tracking step, which converts the tiles its windows read;
//   track_frame_whole  the same with every tile converted first (as before conversion by tiles):
//                      its ratio to track_frame is what converting on demand saves.
#include <memory>
#include <stdexcept>
#include <vector>

#include "bench/bench.h"
#include "bench/simulated_sequence.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/offline/sequence.h"

namespace epichead::bench {
namespace {

struct TrackCycle {
  std::unique_ptr<vision::Sequence> seq;
  std::unique_ptr<vision::ModelTracker> tracker;
  std::vector<vision::WindowImage> images;
  std::vector<Eigen::Isometry3d> truth;
  vision::FrameReport report;
  std::size_t next = 0;
};

const Registration track_cycle{"track_cycle", [] {
  SimulatedSequence sim = simulate_builtin("mockup_walk", 24);
  auto s = std::make_shared<TrackCycle>();
  s->seq = std::move(sim.seq);
  s->images.resize(sim.frames.size());
  for (std::size_t i = 0; i < s->images.size(); ++i) {
    if (auto ok = s->images[i].assign(sim.frames[i]); !ok) throw std::runtime_error(ok.error());
    s->truth.push_back(s->seq->ground_truth()[i].cam_T_obj);
  }
  s->tracker = std::make_unique<vision::ModelTracker>(s->seq->model(), s->seq->camera());
  // Each frame is predicted at the previous frame's true pose (the motion of one frame
  // interval is left for the windows to find), so the work is that of real tracking.
  return [s] {
    const std::size_t i = s->next;
    s->next = (i + 1) % s->images.size();
    s->tracker->track(s->images[i], s->truth[i == 0 ? 0 : i - 1], s->report);
  };
}};

struct TrackFrame {
  std::unique_ptr<vision::Sequence> seq;
  std::unique_ptr<vision::ModelTracker> tracker;
  std::vector<cv::Mat> frames;
  std::vector<Eigen::Isometry3d> truth;
  vision::WindowImage image;
  vision::FrameReport report;
  std::size_t next = 0;
};

Iteration track_frame(bool whole_frame) {
  SimulatedSequence sim = simulate_builtin("mockup_walk", 24);
  auto s = std::make_shared<TrackFrame>();
  s->seq = std::move(sim.seq);
  s->frames = std::move(sim.frames);
  for (std::size_t i = 0; i < s->frames.size(); ++i) s->truth.push_back(s->seq->ground_truth()[i].cam_T_obj);
  s->tracker = std::make_unique<vision::ModelTracker>(s->seq->model(), s->seq->camera());
  return [s, whole_frame] {
    const std::size_t i = s->next;
    s->next = (i + 1) % s->frames.size();
    if (auto ok = s->image.assign(s->frames[i]); !ok) throw std::runtime_error(ok.error());
    if (whole_frame) s->image.prepare_all();
    s->tracker->track(s->image, s->truth[i == 0 ? 0 : i - 1], s->report);
  };
}

const Registration frame_on_demand{"track_frame", [] { return track_frame(false); }};
const Registration frame_whole{"track_frame_whole", [] { return track_frame(true); }};

}  // namespace
}  // namespace epichead::bench
