#pragma once
// Did the tracker select the right image line for each model edge? Reads the tracker's
// lines.csv (per frame and visible edge: the selected candidate's end points) and compares each
// selection with the edge projected at the ground-truth pose: right when both end points lie
// within max_distance_px of the true edge's line and the directions agree within max_angle_deg.
// Edges with a close parallel neighbour in the image (another visible edge within
// crowded_angle_deg and crowded_distance_px, overlapping along its length: the three stiffeners
// of mockup_walk, the paper's Figs. 18/19) are counted separately: that is where selection by
// local evidence alone goes wrong and validation by the model's topology should not.
#include <expected>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"

namespace epichead::tools {

struct LineSelectionOptions {
  double max_distance_px = 3.0;
  double max_angle_deg = 3.0;
  double crowded_angle_deg = 5.0;
  double crowded_distance_px = 12.0;
};

struct LineSelectionCounts {
  int selections = 0, right = 0;
  double rate() const { return selections ? static_cast<double>(right) / selections : 0.0; }
};

struct LineSelectionScore {
  LineSelectionCounts all, crowded;
  int not_selected = 0;  // visible edges for which the tracker selected nothing
  std::map<int, LineSelectionCounts> crowded_by_frame;  // for picking a frame to show
};

std::expected<LineSelectionScore, std::string> score_line_selection(const std::string& lines_csv, const vision::Sequence& seq,
                                                                    const std::vector<vision::StampedPose>& truth,
                                                                    const LineSelectionOptions& options = {});

nlohmann::json to_json(const LineSelectionScore& s);

}  // namespace epichead::tools
