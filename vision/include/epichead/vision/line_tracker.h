#pragma once
// Per-frame line tracking: one EPIC window per visible model edge, per-feature cue references
// kept across frames, and the selected line of each feature. Allocation-free after warm-up
// (each feature's buffers are reserved the first time it is seen).
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/epic.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/visibility.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

// Where a feature's window is placed.
enum class WindowPlacement {
  Previous,    // on the feature's previous result when it was found, else on the projection
  Projection,  // always on the projection (a given or predicted pose)
};

struct LineTrackerOptions {
  WindowOptions window;
  EpicOptions epic;
  EpicMode mode = EpicMode::Epic;
  // The selected candidate counts as found with inliers in at least this fraction of the
  // window's rows. Without topology validation (later step) this is what rejects a chance
  // alignment of a few edgels; 0.3 keeps a line that is 70% occluded.
  float min_support_ratio = 0.3f;
};

// State and latest result of one model edge.
struct LineFeature {
  int edge = -1;                 // index into CadModel::edges
  bool visible = false;          // a window was placed this frame
  bool found = false;            // a candidate was selected this frame
  ObjectSide side = ObjectSide::Both;
  Eigen::Vector2d window_a_px = Eigen::Vector2d::Zero(), window_b_px = Eigen::Vector2d::Zero();  // window placed on a->b
  int selected = -1;             // index into result.candidates, -1 when not found
  EpicResult result;
  FeatureReferences refs;
  bool has_previous = false;     // previous_a/b hold last frame's selected line
  Eigen::Vector2d previous_a_px = Eigen::Vector2d::Zero(), previous_b_px = Eigen::Vector2d::Zero();
  bool reserved = false;
};

class LineTracker {
 public:
  explicit LineTracker(const LineTrackerOptions& options = {});
  const LineTrackerOptions& options() const { return options_; }
  void set_mode(EpicMode mode) { options_.mode = mode; }

  // Tracks one frame. Each model edge uses its longest visible piece in `visible` (the
  // projection and the ObjectSide); references are initialised from the projection the first
  // time an edge is seen and updated from every selected candidate (not in gradient mode).
  void track(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement);
  // Indexed by model edge; only entries with visible == true were processed this frame.
  const std::vector<LineFeature>& features() const { return features_; }
  // Forgets all references and previous results.
  void reset();

 private:
  void track_one(const WindowImage& image, const VisibleEdge& piece, WindowPlacement placement, LineFeature& f);
  LineTrackerOptions options_;
  LineWindow window_;
  EpicDetector detector_;
  std::vector<LineFeature> features_;
  std::vector<int> longest_;  // per edge: index of its longest visible piece this frame
};

}  // namespace epichead::vision
