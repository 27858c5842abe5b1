#pragma once
// Per-frame tracking of the model's circles (projected ellipses) with EPIC tracker lines:
// placement on the previous fit (or the projection), EPIC on all tracker lines of an ellipse
// in one window, RANSAC ellipse candidates, and occlusion handling by arcs. When a run of
// neighbouring tracker lines misses the ellipse the others agree on, the ellipse becomes the
// arc of the lines that found it, the lines are re-spread over that arc, and one extra line
// beyond each end watches for the occluder to leave; the arc grows back line by line. An arc
// under 180 deg is flagged weak: an ellipse fitted to it is poorly constrained.
// Allocation-free after warm-up (each feature's buffers are reserved when first seen).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/ellipse.h"
#include "epichead/vision/ellipse_fit.h"
#include "epichead/vision/epic.h"
#include "epichead/vision/line_tracker.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/tracker_lines.h"
#include "epichead/vision/visibility.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

// Which side of a projected circle the object is on (the ObjectSide of its tracker lines).
enum class RimSide {
  Inside,   // a disc, or a rim whose surface is seen inside its image (a lamp shade from above)
  Outside,  // a hole in a surface
  Both,
  Model,    // what the model says for each rim at the pose (VisibleEllipse::side, rim_side.h)
};

struct EllipseTrackerOptions {
  int lines = 30;        // tracker lines per ellipse (the paper's ~30)
  int width_px = 60;     // samples across the contour (the paper's 60 px)
  EpicOptions epic;      // edgels, cues, good edgels and reference updates as for lines
  EllipseRansacOptions ransac;
  EpicMode mode = EpicMode::Epic;
  RimSide side = RimSide::Inside;
  // Consecutive tracker lines without an inlier that break the ellipse into an arc: one line
  // may miss by noise or a specular spot, three in a row (36 deg of 30 lines) is an occluder.
  int min_gap_lines = 3;
  // Found: inliers on at least this fraction of the placed lines (and ransac.min_support).
  float min_support_ratio = 0.3f;
  // An arc that subtends less than this is weak (the fit is unstable there).
  double weak_arc_rad = 3.14159265358979323846;
  // Down-weighting of a weak arc for the pose: its EllipseObservation sigma_px is multiplied.
  double weak_sigma_factor = 3.0;
  double sigma_px = 1.0;  // EllipseObservation sigma of a strong (>= 180 deg) ellipse
  // Largest changes of a fitted ellipse from the one its lines were placed on (the prediction
  // or the last fit): of its semi-major axis, relative (0.1: the circle 10 % nearer or
  // further), and of its openness, semi-minor / semi-major (0.1: the line of sight turned ~6 deg
  // against the circle).
  double max_size_change = 0.1;
  double max_openness_change = 0.1;
};

// Why a visible circle's ellipse was not found this frame: the best-supported candidate's
// reason, or that there was none. On a start from init.csv a can's rims are refused for these
// reasons while its silhouettes are found; report.json counts them per frame.
enum class EllipseRefusal : std::uint8_t {
  None,          // found, or no tracker lines placed
  NoCandidate,   // RANSAC fitted no ellipse to the good edgels
  LeavesWindow,  // the candidate leaves the window of an arc line (EllipseTracker::plausible)
  OtherShape,    // its size or openness is another contour's (max_size_change, max_openness_change)
  FewLines,      // its inliers lie on too few tracker lines (min_support_ratio)
};
const char* to_string(EllipseRefusal refusal);

// State and latest result of one model circle.
struct EllipseFeature {
  int circle = -1;                // index into CadModel::circles
  bool visible = false;           // tracker lines were placed this frame
  bool found = false;             // an ellipse was selected this frame
  bool weak = false;              // the found arc subtends less than weak_arc_rad
  EllipseRefusal refused = EllipseRefusal::None;  // why a visible circle was not found
  ObjectSide side = ObjectSide::Left;
  Ellipse placed_on;              // the ellipse the tracker lines were placed on
  EllipseArc placed_arc;          // ... and the arc they were spread over
  int arc_row_begin = 0, arc_row_end = 0;  // rows of the arc lines; the others are the two extension lines
  std::vector<TrackerLine> lines;          // this frame's rows (extension, arc lines, extension)
  EpicResult result;                       // edgels, intervals, good edgels of all rows
  std::vector<EllipseFit> candidates;      // best support first; inliers index result.edgels
  std::vector<int> candidate_inliers;      // edgel indices of the candidates
  int selected = -1;                       // index into candidates, -1 when not found
  std::vector<unsigned char> row_hit;      // per row: holds an inlier of the selected ellipse
  EllipseArc arc;                          // the arc found this frame (where the next lines go)
  Ellipse ellipse;                         // the selected fit
  FeatureReferences refs;
  bool has_previous = false;               // ellipse/arc are where the next frame starts
  int occlusions = 0, recoveries = 0;      // counters: full -> arc, arc -> full
  int ransac_iterations = 0;
  bool reserved = false;
  // Inlier edgels of the selected ellipse (0 when not found).
  int inlier_count() const { return selected < 0 ? 0 : candidates[static_cast<std::size_t>(selected)].support; }
};

class EllipseTracker {
 public:
  explicit EllipseTracker(const EllipseTrackerOptions& options = {});
  const EllipseTrackerOptions& options() const { return options_; }
  void set_mode(EpicMode mode) { options_.mode = mode; }
  // As LineTracker::set_outline: the object's region weighs the rims' outline edgels.
  void set_outline(const ObjectRegion* region) { outline_region_ = region; }

  // Tracks one frame: every ellipse of `visible` (references initialised from the projection
  // the first time a circle is seen).
  void track(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement);
  // Tracks one ellipse given directly (tests, benchmarks): `circle` indexes the features.
  // With RimSide::Model the side is `model_side` (Both when not given). Tracker lines go only
  // on `seen` (VisibleEllipse::seen: the part the model's own faces leave in view).
  void track_one(const WindowImage& image, int circle, const Ellipse& projection, WindowPlacement placement,
                 ObjectSide model_side = ObjectSide::Both, const EllipseArc& seen = {});
  // Indexed by model circle; only entries with visible == true were processed this frame.
  const std::vector<EllipseFeature>& features() const { return features_; }
  // Image point of an edgel of a feature's result.
  Eigen::Vector2d edgel_px(const EllipseFeature& f, int edgel) const;
  // The pose estimator's observation of a found feature: its inlier edgel points, sigma_px
  // raised by weak_sigma_factor on a weak arc. False (out untouched) when not found.
  bool observation(const EllipseFeature& f, const ModelCircle& circle, EllipseObservation& out) const;
  // Forgets references, previous fits and arcs.
  void reset();

 private:
  EllipseFeature& feature(int circle);
  bool place(const WindowImage& image, EllipseFeature& f, const Ellipse& on, const EllipseArc& arc);
  void fit(EllipseFeature& f);
  // Whether e crosses every arc line inside its window.
  bool plausible(const EllipseFeature& f, const Ellipse& e) const;
  // Whether e has the size and openness of the ellipse the lines were placed on.
  bool placed_shape(const EllipseFeature& f, const Ellipse& e) const;
  // The placed ellipse moved (shift, and scale within max_size_change) onto the good edgels
  // most of which it explains; false when fewer than five. Appends its inliers to
  // f.candidate_inliers.
  bool moved_placement(EllipseFeature& f, EllipseFit& out) const;
  void update_arc(EllipseFeature& f);
  EllipseTrackerOptions options_;
  TrackerLineWindow window_;
  EpicDetector detector_;
  EllipseRansac ransac_;
  std::vector<EllipseFeature> features_;
  std::vector<double> px_x_, px_y_;  // scratch: good edgels in the image
  const ObjectRegion* outline_region_ = nullptr;
  std::vector<std::int8_t> outer_side_;  // per tracker line, while outline_region_ is set
  std::vector<int> px_row_;
  LineCandidate update_;             // scratch: the selected ellipse's inliers as an EPIC candidate
};

}  // namespace epichead::vision
