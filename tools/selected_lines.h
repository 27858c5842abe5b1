#pragma once
// The line each visible model edge ended with in a frame: the candidate the tracker chose
// before the pose judged it (validation's pick, or without validation the strongest) and
// whether the pose kept it. What `track` writes to lines.csv and draws, and what the Python
// module's FrameResult.lines holds.
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/model_tracker.h"

namespace epichead::tools {

struct SelectedLine {
  int edge = -1;        // model edge (CadModel::edges)
  int candidates = 0;   // candidate lines EPIC found in its window
  int chosen = -1;      // index of the chosen candidate, -1 when none
  bool found = false;   // a candidate was chosen
  bool inlier = false;  // ... and the pose kept it (never on a lost frame)
  Eigen::Vector2d a_px = Eigen::Vector2d::Zero(), b_px = Eigen::Vector2d::Zero();  // the chosen line
  int support = 0;      // its inlier edgels
};

// The candidate the tracker chose for feature `f` (the tracker marks a pose outlier unselected
// afterwards, so LineFeature::selected alone would hide the wrong choices), or -1.
int chosen_candidate(const vision::ModelTracker& tracker, const vision::LineFeature& f);
// One entry per visible edge of the last tracked frame, in edge order.
void selected_lines(const vision::ModelTracker& tracker, const vision::FrameReport& report, std::vector<SelectedLine>& out);

}  // namespace epichead::tools
