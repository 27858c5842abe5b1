#pragma once
// Per-frame line tracking: one EPIC window per visible model edge, per-feature cue references
// kept across frames, and the selected line of each feature. Allocation-free after warm-up
// (each feature's buffers are reserved the first time it is seen, or all at once by reserve()).
//
// Two ways to use it: track() detects and takes each window's best candidate at once (line
// tracking on its own); detect() followed by accept()/reject() per feature lets a later step
// (topology validation, the pose's outlier test) choose the candidate before the feature's cue
// references learn from it.
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
  // On the projection, but an ellipse found on an arc last frame (partly occluded) is looked
  // for on that arc, with the extension lines beyond its ends that see the occluder leave;
  // lines as Projection. What the full tracker uses.
  ProjectionOnArc,
};

struct LineTrackerOptions {
  WindowOptions window;
  EpicOptions epic;
  EpicMode mode = EpicMode::Epic;
  // The selected candidate counts as found with inliers in at least this fraction of the
  // window's rows. Without topology validation (later step) this is what rejects a chance
  // alignment of a few edgels; 0.3 keeps a line that is 70% occluded.
  float min_support_ratio = 0.3f;
  // EPIC's look-through of empty intervals (EpicDetector::detect) for every edge that has no
  // other visible model edge within parallel_reach_deg of its direction and half a window width
  // of it (such an edge could be the neighbour a thin strip separates). A contour with a printed
  // border or a blurred bevel then keeps the contour instead of the border's inner edge.
  bool look_through = true;
  double parallel_reach_deg = 10.0;
};

// State and latest result of one model edge.
struct LineFeature {
  int edge = -1;                 // index into CadModel::edges
  bool visible = false;          // a window was placed this frame
  bool found = false;            // a candidate was selected this frame
  VisibleEdge piece;             // the projected piece the window was derived from (when visible)
  ObjectSide side = ObjectSide::Both;
  Eigen::Vector2d window_a_px = Eigen::Vector2d::Zero(), window_b_px = Eigen::Vector2d::Zero();  // window placed on a->b
  int selected = -1;             // index into result.candidates, -1 when not found
  // Candidates are only those with at least min_support_ratio of the rows as inliers (detect()
  // drops the rest), so every candidate is a plausible line.
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
  // The object's region to weigh outline edgels with (EpicDetector::detect's OutlineEvidence),
  // or nullptr (the default): not owned, must outlive the detect() calls it is set for.
  void set_outline(const ObjectRegion* region) { outline_region_ = region; }

  // Tracks one frame. Each model edge uses its longest visible piece in `visible` (the
  // projection and the ObjectSide); references are initialised from the projection the first
  // time an edge is seen and updated from every selected candidate (not in gradient mode).
  void track(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement);
  // Places the windows and runs EPIC like track(), but selects nothing and learns nothing:
  // features with candidates have selected = 0 and found = false until accept() or reject().
  void detect(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement);
  // Selects candidate `candidate` of feature `edge`: it becomes the feature's previous line and
  // its inlier edgels update the cue references (except in gradient mode).
  void accept(int edge, int candidate);
  // The feature found nothing usable this frame: its next window returns to the projection.
  void reject(int edge);
  // Indexed by model edge; only entries with visible == true were processed this frame.
  const std::vector<LineFeature>& features() const { return features_; }
  // Detection window of the tracker, for other steps that sample the same image.
  const WindowOptions& window_options() const { return options_.window; }
  // Forgets all references and previous results.
  void reset();
  // Sizes the buffers of the features of `edges` model edges now (set-up), instead of the
  // first time each is seen (the first frame).
  void reserve(int edges);

 private:
  // features_ (and longest_) for edge indices below `edges`.
  void grow_to(int edges);
  // A feature's window buffers, sized the first time only.
  void reserve_buffers(LineFeature& f) const;
  void detect_one(const WindowImage& image, const VisibleEdge& piece, WindowPlacement placement, bool look_through,
                  LineFeature& f);
  bool has_close_parallel(const VisibleModel& visible, int edge) const;
  LineTrackerOptions options_;
  LineWindow window_;
  EpicDetector detector_;
  std::vector<LineFeature> features_;
  std::vector<int> longest_;  // per edge: index of its longest visible piece this frame
  const ObjectRegion* outline_region_ = nullptr;
  std::vector<std::int8_t> outer_side_;  // per window row, while outline_region_ is set
};

}  // namespace epichead::vision
