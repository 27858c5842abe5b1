#pragma once
// Overlay PNG of one tracked frame: the model drawn at ViSP's pose by epichead's own
// projection (on the original, distorted frame, so it is comparable with our tracker's
// overlays), ViSP's moving-edge sites and KLT points, and a caption with the verdict.
#include <expected>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/visibility.h"
#include "undistorter.h"
#include "visp_tracker.h"

namespace epichead::visp_compare {

class OverlayWriter {
 public:
  OverlayWriter(const vision::CadModel& model, const vision::Camera& camera);
  std::expected<void, std::string> write(const std::string& path, const cv::Mat& frame, int frame_number,
                                         const FrameResult& result, const std::vector<DisplayFeature>& features,
                                         const Undistorter& undistorter);

 private:
  vision::Visibility visibility_;
  vision::VisibleModel visible_;
  cv::Mat canvas_;
};

}  // namespace epichead::visp_compare
