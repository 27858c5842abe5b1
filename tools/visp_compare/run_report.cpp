#include "run_report.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include <nlohmann/json.hpp>

namespace epichead::visp_compare {
namespace {

// JSON has no NaN: absent numbers are null.
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json settings_json(const TrackerSettings& s) {
  return {{"me_mask_size", s.me_mask_size},
          {"me_mask_count", s.me_mask_count},
          {"me_range_px", s.me_range_px},
          {"me_threshold", s.me_threshold},
          {"me_mu1", s.me_mu1},
          {"me_mu2", s.me_mu2},
          {"me_sample_step_px", s.me_sample_step_px},
          {"klt_max_features", s.klt_max_features},
          {"klt_window_px", s.klt_window_px},
          {"klt_quality", s.klt_quality},
          {"klt_min_distance_px", s.klt_min_distance_px},
          {"klt_harris_k", s.klt_harris_k},
          {"klt_block_size_px", s.klt_block_size_px},
          {"klt_pyramid_levels", s.klt_pyramid_levels},
          {"klt_mask_border_px", s.klt_mask_border_px},
          {"angle_appear_deg", s.angle_appear_deg},
          {"angle_disappear_deg", s.angle_disappear_deg},
          {"near_clip_m", s.near_clip_m},
          {"max_projection_error_deg", s.max_projection_error_deg}};
}

}  // namespace

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const double rank = std::ceil(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size()));
  const std::size_t index = rank < 1 ? 0 : static_cast<std::size_t>(rank) - 1;
  return values[std::min(index, values.size() - 1)];
}

std::expected<void, std::string> write_report(const std::string& path, const std::string& sequence_dir,
                                              TrackerMode mode, const TrackerSettings& settings,
                                              const std::vector<FrameRecord>& frames, unsigned reinitialisations) {
  std::vector<double> track_ms, track_cpu_ms;
  track_ms.reserve(frames.size());
  track_cpu_ms.reserve(frames.size());
  int tracked = 0;
  nlohmann::json per_frame = nlohmann::json::array();
  for (const auto& f : frames) {
    const auto& r = f.result;
    track_ms.push_back(r.track_ms);
    track_cpu_ms.push_back(r.track_cpu_ms);
    tracked += r.status == FrameStatus::tracked;
    per_frame.push_back({{"frame", f.frame},
                         {"status", r.status == FrameStatus::tracked ? "tracked" : "lost"},
                         {"track_ms", r.track_ms},
                         {"track_cpu_ms", r.track_cpu_ms},
                         {"projection_error_deg", number(r.projection_error_deg)},
                         {"edge_features", r.edge_features},
                         {"klt_features", r.klt_features},
                         {"reason", r.reason}});
  }
  const nlohmann::json report{{"tracker", "ViSP vpMbGenericTracker " + visp_version()},
                              {"sequence", sequence_dir},
                              {"mode", mode_name(mode)},
                              {"frames", static_cast<int>(frames.size())},
                              {"tracked", tracked},
                              {"lost", static_cast<int>(frames.size()) - tracked},
                              {"reinitialisations", reinitialisations},
                              {"track_ms_median", number(percentile(track_ms, 0.5))},
                              {"track_ms_p99", number(percentile(track_ms, 0.99))},
                              {"track_cpu_ms_median", number(percentile(track_cpu_ms, 0.5))},
                              {"track_cpu_ms_p99", number(percentile(track_cpu_ms, 0.99))},
                              {"settings", settings_json(settings)},
                              {"per_frame", per_frame}};
  std::ofstream out(path);
  if (!out) return std::unexpected(path + ": cannot open for writing");
  out << report.dump(1) << "\n";
  if (!out) return std::unexpected(path + ": write error");
  return {};
}

}  // namespace epichead::visp_compare
