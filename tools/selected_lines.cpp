#include "selected_lines.h"

namespace epichead::tools {

int chosen_candidate(const vision::ModelTracker& tracker, const vision::LineFeature& f) {
  if (tracker.options().mode == vision::TrackMode::EpicValidation)
    return tracker.validation().selected[static_cast<std::size_t>(f.edge)];
  return f.result.candidates.empty() ? -1 : 0;
}

void selected_lines(const vision::ModelTracker& tracker, const vision::FrameReport& report, std::vector<SelectedLine>& out) {
  out.clear();
  const auto& residuals = tracker.pose().residuals;
  for (const vision::LineFeature& f : tracker.lines().features()) {
    if (!f.visible) continue;
    SelectedLine s;
    s.edge = f.edge;
    const auto& cands = f.result.candidates;
    s.candidates = static_cast<int>(cands.size());
    const int chosen = chosen_candidate(tracker, f);
    s.found = chosen >= 0 && chosen < s.candidates;
    if (s.found) {
      const vision::LineCandidate& c = cands[static_cast<std::size_t>(chosen)];
      s.chosen = chosen;
      s.a_px = c.a_px;
      s.b_px = c.b_px;
      s.support = c.support;
    }
    s.inlier = s.found && report.status != vision::TrackStatus::Lost && static_cast<std::size_t>(f.edge) < residuals.size() &&
               residuals[static_cast<std::size_t>(f.edge)].inlier;
    out.push_back(s);
  }
}

}  // namespace epichead::tools
