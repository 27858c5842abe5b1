#include "overlay.h"

#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/offline/overlay.h"

namespace epichead::visp_compare {

OverlayWriter::OverlayWriter(const vision::CadModel& model, const vision::Camera& camera)
    : visibility_(model, camera) {}

std::expected<void, std::string> OverlayWriter::write(const std::string& path, const cv::Mat& frame,
                                                      int frame_number, const FrameResult& result,
                                                      const std::vector<DisplayFeature>& features,
                                                      const Undistorter& undistorter) {
  if (frame.channels() == 1) cv::cvtColor(frame, canvas_, cv::COLOR_GRAY2BGR);
  else if (frame.channels() == 4) cv::cvtColor(frame, canvas_, cv::COLOR_BGRA2BGR);
  else frame.copyTo(canvas_);

  visibility_.compute(result.cam_T_obj, visible_);
  vision::draw_visible_model(canvas_, visible_);
  for (const auto& f : features) {
    const Eigen::Vector2d px = undistorter.to_original_px(f.px);
    const cv::Point at(static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y())));
    switch (f.kind) {
      case DisplayFeature::Kind::edge_site_good: cv::circle(canvas_, at, 1, {0, 255, 0}, cv::FILLED); break;
      case DisplayFeature::Kind::edge_site_rejected: cv::circle(canvas_, at, 1, {0, 0, 255}, cv::FILLED); break;
      case DisplayFeature::Kind::klt_point: cv::drawMarker(canvas_, at, {255, 128, 0}, cv::MARKER_CROSS, 5); break;
    }
  }
  const bool tracked = result.status == FrameStatus::tracked;
  char caption[160];
  std::snprintf(caption, sizeof caption, "ViSP frame %d  %s  proj.err %.1f deg  edge sites %u  klt %u  %.2f ms",
                frame_number, tracked ? "tracked" : "LOST (last good pose)", result.projection_error_deg,
                result.edge_features, result.klt_features, result.track_ms);
  cv::putText(canvas_, caption, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              tracked ? cv::Scalar(255, 255, 255) : cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
  cv::putText(canvas_, "sites: green kept, red rejected; KLT: blue crosses", {8, canvas_.rows - 8},
              cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 255, 255}, 1, cv::LINE_AA);
  try {
    if (!cv::imwrite(path, canvas_)) return std::unexpected(path + ": cannot write");
  } catch (const cv::Exception& e) {
    return std::unexpected(path + ": cannot write: " + e.what());
  }
  return {};
}

}  // namespace epichead::visp_compare
