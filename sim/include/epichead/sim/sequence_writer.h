#pragma once
// Runs a scenario and writes a sequence directory (DESIGN.md) that vision::Sequence::open reads:
// camera.yaml, model.cao, frames/NNNNNN.png, frames.csv, init.csv, gt.csv, imu.csv, plus the
// simulator's own truth: imu_true.csv, sim_truth.json and scenario.scn.
#include <expected>
#include <functional>
#include <string>

#include "epichead/sim/scenario.h"

namespace epichead::sim {

struct SimSummary {
  int frames = 0;
  double duration_s = 0;              // first to last frame
  double peak_body_rate_degps = 0;    // largest body angular rate from frame 0 to the last frame
  int imu_samples = 0, imu_dropped = 0, imu_saturated = 0;
};

// Called after each frame is written (frame index, frame count), e.g. for a progress line.
using FrameProgress = std::function<void(int frame, int frames)>;

// Writes the sequence into out_dir (created if needed). A non-empty out_dir that is not an
// earlier simulator output is refused, so a typo cannot overwrite someone's data.
// Deterministic: the same scenario (and seed) gives byte-identical files.
std::expected<SimSummary, std::string> write_sequence(const Scenario& scenario, const std::string& out_dir,
                                                      const FrameProgress& progress = {});

}  // namespace epichead::sim
