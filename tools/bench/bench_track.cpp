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

// What an iteration starts from: window images made before the clock (track_cycle), or the
// frame itself, taken into one window image per iteration (track_frame, and with every tile
// converted first, track_frame_whole).
enum class Start { ConvertedImage, FrameOnDemand, FrameWhole };

struct TrackBench {
  std::unique_ptr<vision::Sequence> seq;
  std::unique_ptr<vision::ModelTracker> tracker;
  std::vector<cv::Mat> frames;
  std::vector<vision::WindowImage> images;  // ConvertedImage: one per frame
  vision::WindowImage image;                // otherwise: the one the frames are taken into
  std::vector<Eigen::Isometry3d> truth;
  vision::FrameReport report;
  std::size_t next = 0;
};

Iteration track_bench(Start start) {
  SimulatedSequence sim = simulate_builtin("mockup_walk", 24);
  auto s = std::make_shared<TrackBench>();
  s->seq = std::move(sim.seq);
  s->frames = std::move(sim.frames);
  for (std::size_t i = 0; i < s->frames.size(); ++i) s->truth.push_back(s->seq->ground_truth()[i].cam_T_obj);
  if (start == Start::ConvertedImage) {
    s->images.resize(s->frames.size());
    for (std::size_t i = 0; i < s->images.size(); ++i)
      if (auto ok = s->images[i].assign(s->frames[i]); !ok) throw std::runtime_error(ok.error());
  }
  s->tracker = std::make_unique<vision::ModelTracker>(s->seq->model(), s->seq->camera());
  // Each frame is predicted at the previous frame's true pose (the motion of one frame
  // interval is left for the windows to find), so the work is that of real tracking.
  return [s, start] {
    const std::size_t i = s->next;
    s->next = (i + 1) % s->frames.size();
    vision::WindowImage* image = &s->image;
    if (start == Start::ConvertedImage) {
      image = &s->images[i];
    } else {
      if (auto ok = s->image.assign(s->frames[i]); !ok) throw std::runtime_error(ok.error());
      if (start == Start::FrameWhole) s->image.prepare_all();
    }
    s->tracker->track(*image, s->truth[i == 0 ? 0 : i - 1], s->report);
  };
}

const Registration track_cycle{"track_cycle", [] { return track_bench(Start::ConvertedImage); }};
const Registration frame_on_demand{"track_frame", [] { return track_bench(Start::FrameOnDemand); }};
const Registration frame_whole{"track_frame_whole", [] { return track_bench(Start::FrameWhole); }};

}  // namespace
}  // namespace epichead::bench
