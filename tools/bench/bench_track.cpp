// The full tracking cycle (visibility, EPIC windows, validation, pose, reference update) on a
// short built-in mockup_walk sequence (25+ visible lines), one frame per iteration.
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <vector>

#include <unistd.h>

#include "bench/bench.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sequence_writer.h"
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
  auto scenario = sim::find_scenario("mockup_walk");
  if (!scenario) throw std::runtime_error(scenario.error());
  scenario->frames = 24;
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("epichead-bench-track-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  if (auto written = sim::write_sequence(*scenario, dir.string()); !written) throw std::runtime_error(written.error());
  auto seq = vision::Sequence::open(dir.string());
  if (!seq) throw std::runtime_error(seq.error());
  auto s = std::make_shared<TrackCycle>();
  s->seq = std::make_unique<vision::Sequence>(std::move(*seq));
  s->images.resize(s->seq->frame_count());
  for (std::size_t i = 0; i < s->images.size(); ++i) {
    auto frame = s->seq->read_frame(i);
    if (!frame) throw std::runtime_error(frame.error());
    if (auto ok = s->images[i].assign(*frame); !ok) throw std::runtime_error(ok.error());
    s->truth.push_back(s->seq->ground_truth()[i].cam_T_obj);
  }
  std::filesystem::remove_all(dir);
  s->tracker = std::make_unique<vision::ModelTracker>(s->seq->model(), s->seq->camera());
  // Each frame is predicted at the previous frame's true pose (the motion of one frame
  // interval is left for the windows to find), so the work is that of real tracking.
  return [s] {
    const std::size_t i = s->next;
    s->next = (i + 1) % s->images.size();
    s->tracker->track(s->images[i], s->truth[i == 0 ? 0 : i - 1], s->report);
  };
}};

}  // namespace
}  // namespace epichead::bench
