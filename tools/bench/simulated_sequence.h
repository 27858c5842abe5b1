#pragma once
// A built-in scenario simulated into a temporary directory and read back for a benchmark's
// set-up: the sequence (model, camera, ground truth) and its frames in memory; the directory
// is gone afterwards.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "epichead/vision/offline/sequence.h"

namespace epichead::bench {

struct SimulatedSequence {
  std::unique_ptr<vision::Sequence> seq;
  std::vector<cv::Mat> frames;
};

// Throws std::runtime_error with the simulator's or the reader's message.
SimulatedSequence simulate_builtin(const std::string& scenario, int frames);

}  // namespace epichead::bench
