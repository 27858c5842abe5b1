#pragma once
// The per-frame model-based tracker (DESIGN.md steps 1-6): visibility at the predicted pose ->
// line windows (EPIC) -> RANSAC candidates -> topology validation -> robust pose -> cue
// reference update of the features the pose accepted. The caller supplies the prediction (the
// Kalman predictor, a constant-velocity model, or the last pose) and gets the pose, its
// covariance, a status with reasons, per-stage timings and feature counts. After warm-up (the
// first frames, while buffers grow to their working size) a frame allocates nothing.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/line_tracker.h"
#include "epichead/vision/object_region.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/rim_side.h"
#include "epichead/vision/topology_validator.h"
#include "epichead/vision/visibility.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

// What selects each feature's line (for measuring the gain of each step).
enum class TrackMode {
  Gradient,        // nearest strong gradient per row, no cues, no validation
  Epic,            // EPIC cues, the best RANSAC candidate
  EpicValidation,  // EPIC cues, several candidates, topology validation selects
};
const char* to_string(TrackMode mode);

enum class TrackStatus { Tracked, Degraded, Lost };
const char* to_string(TrackStatus status);

// Why a frame is not simply "tracked" (bits; several may be set).
enum class TrackReason : std::uint32_t {
  None = 0,
  NotVisible = 1u << 0,      // the model projects to (almost) nothing at the prediction
  FewFeatures = 1u << 1,     // fewer than min_features lines found
  PoseFailed = 1u << 2,      // the estimator reported too few features, degeneracy or divergence
  FewInliers = 1u << 3,      // the pose explains less than min_inlier_ratio of the found lines
  HighResidual = 1u << 4,    // robust residual scale above max_scale_px
  Jump = 1u << 5,            // the pose moved implausibly far from the prediction
  Reacquired = 1u << 6,      // tracked again after a loss (informational)
  AgainstGravity = 1u << 7,  // set by the caller with an IMU: the pose tilts the object away from
                             // the down the accelerometer measures (a wrong lock; fusion/learnt_gravity.h)
  AgainstImageMotion = 1u << 8,  // set by the caller without an IMU: the pose puts the object away from
                                 // where the frame's own motion shows it (a wrong lock; tools/image_motion.h)
  AgainstCarriedTurn = 1u << 9,  // set by the caller with an IMU, while its filter has forgotten its state after
                                 // a long loss: the pose is turned away from the orientation the gyro carried
                                 // (fusion/carried_orientation.h)
};
constexpr TrackReason operator|(TrackReason a, TrackReason b) {
  return static_cast<TrackReason>(static_cast<std::uint32_t>(a) | static_cast<std::uint32_t>(b));
}
constexpr bool has(TrackReason set, TrackReason r) {
  return (static_cast<std::uint32_t>(set) & static_cast<std::uint32_t>(r)) != 0;
}
// "few_features+pose_failed", or "" for None.
std::string to_string(TrackReason reasons);

struct ModelTrackerOptions {
  TrackMode mode = TrackMode::EpicValidation;
  LineTrackerOptions lines;
  // Model circles: tracker lines, ellipse RANSAC and arcs (ellipse_tracker.h). Each rim's
  // object side comes from the faces that meet it (rim_side.h), as a line's from its faces.
  EllipseTrackerOptions ellipses = [] { EllipseTrackerOptions e; e.side = RimSide::Model; return e; }();
  ValidationOptions validation;
  PoseOptions pose;
  VisibilityOptions visibility;
  int min_features = 4;            // lines needed for a pose (three fix it; one spare against a bad one);
                                   // a found ellipse counts as two lines
  double min_inlier_ratio = 0.5;   // below this share of found lines explained: degraded
  double max_scale_px = 2.5;       // robust residual scale above this: degraded (blur, partial fits);
                                   // above twice this the pose explains nothing: lost
  double max_jump_px = 60.0;       // mean model-vertex motion from the prediction above this: lost
  bool use_junctions = true;       // junction points from validation enter the pose (validation mode)
  // Edgels per line given to the pose, evenly spread over the line's inliers. A line has two
  // degrees of freedom; beyond ~10 edgels more only cost time (the errors of neighbouring
  // edgels of one blurred edge are correlated, so they add little information either).
  int max_edgels_per_line = 10;
  // A body of revolution modelled by facets (revolution_axis.h): the pose leaves its turn about
  // the axis to the prediction and its covariance says the turn is unknown. Found from the
  // model when true; off for every model when false.
  bool free_turn_of_revolution = true;
  // Model edges that are chords of a model circle (a rim modelled by facets as well as by its
  // circle) are not tracked as lines while the circle is tracked as an ellipse.
  bool circles_replace_chords = true;
  // The first frame (and the first after a reset or a loss) is measured from the start pose
  // and from a gradient pass's pose, and the better supported start kept (settle()).
  bool settle = true;
  // On the first frame after a start (not after a loss), whose cue references come only from
  // the start pose, the model drawn at it gives object and background colours (object_region.h),
  // and edgels on the outline whose far side looks like the object weigh little: the references
  // cannot yet tell a rim from a printed border just inside it (a can's label), the colours can.
  // Not in the detector's own trackers (a hypothesis can be too far off).
  bool outline_colours = true;
  ObjectRegionOptions outline;
};

// Per-stage wall time of one frame, milliseconds.
struct StageTimes {
  double visibility_ms = 0, epic_ms = 0, validation_ms = 0, pose_ms = 0, total_ms = 0;
  // Adds another measurement's stage times (not its total: a frame's total is timed as a whole).
  void add_stages(const StageTimes& o) {
    visibility_ms += o.visibility_ms;
    epic_ms += o.epic_ms;
    validation_ms += o.validation_ms;
    pose_ms += o.pose_ms;
  }
};

// Visible circles whose ellipse was not found, by the reason (EllipseRefusal).
struct EllipseRefusals {
  int no_candidate = 0, leaves_window = 0, other_shape = 0, few_lines = 0;
};

// How a start (init.csv, a detection, the first frame after a loss) was settled (settle()):
// measured from the given pose and from a gradient pass's pose, the better supported kept.
// Support is the share of found features the pose kept (a line counts one, an ellipse two).
struct StartSettle {
  bool settled = false;          // this frame was a start and settle() ran
  bool kept_gradient = false;    // the frame was measured from the gradient pass's pose
  std::optional<double> support_given, support_gradient;  // empty: that measurement was unusable
};

struct FrameReport {
  TrackStatus status = TrackStatus::Lost;
  TrackReason reasons = TrackReason::None;
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();  // the estimate (the prediction when lost)
  // Left perturbation (t, r), in m and rad: the pose estimator's, with each line's shared error
  // (PoseOptions::line_shared_sigma_px, a smooth body's facets): what a filter is given, and
  // what `track` writes to vision_covariance.csv for `score --covariance` to check.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
  PoseStatus pose_status = PoseStatus::Ok;
  double scale_px = 0;             // robust residual scale of the pose
  int pose_iterations = 0;         // Levenberg-Marquardt iterations over all rejection rounds
  int visible = 0;                 // line windows placed
  int found = 0;                   // windows with at least one candidate
  int ellipses_visible = 0, ellipses_found = 0, ellipses_weak = 0;  // model circles (weak: arc < 180 deg)
  EllipseRefusals ellipses_refused;
  int validated_changed = 0;       // features where validation chose another than RANSAC's best
  int junctions = 0;               // junction points given to the pose
  int inliers = 0, rejected = 0;   // found lines the pose kept / rejected as outliers
  int recovered = 0;               // lines found and kept that were lost or rejected last frame
  int combinations = 0;            // candidate combinations validation examined
  bool used_fallback = false;      // the pose was measured from the fallback prediction
  StartSettle start;
  StageTimes times;
};

// Whether the image supports the pose well enough to overrule a filter's prediction
// (fusion::PoseSupport::strong): tracked (no reasons), at least 80 % of the found features kept,
// and six constraints or more (a line counts one, an ellipse two). On box_clutter a wrong pose
// from 4 of 7 lines was "tracked"; taking it over the filter's prediction lost the object for good.
bool strongly_supported(const FrameReport& report);

class ModelTracker {
 public:
  ModelTracker(const CadModel& model, const Camera& camera, const ModelTrackerOptions& options = {});
  const ModelTrackerOptions& options() const { return options_; }

  // Tracks one frame from the predicted pose (the init pose on the first frame). `out` is
  // reused between frames.
  void track(const WindowImage& image, const Eigen::Isometry3d& predicted_cam_T_obj, FrameReport& out);
  // The same with a second opinion: when nothing usable is measured from the prediction, the
  // frame is measured again from `fallback` (e.g. the vision-only extrapolation when the IMU's
  // prediction has drifted). nullptr: no second attempt.
  void track(const WindowImage& image, const Eigen::Isometry3d& predicted_cam_T_obj, const Eigen::Isometry3d* fallback,
             FrameReport& out);
  // Forgets every feature's references and history (re-initialisation).
  void reset();

  // Inspection (for overlays and tests): the line features of the last frame, the validation
  // result and the pose result.
  const LineTracker& lines() const { return lines_; }
  const EllipseTracker& ellipses() const { return ellipses_; }
  const ValidationResult& validation() const { return validation_; }
  const PoseResult& pose() const { return pose_; }
  const VisibleModel& visible() const { return visible_; }
  // The body of revolution's axis whose turn the pose leaves free, or nothing.
  const std::optional<RevolutionAxis>& free_turn() const { return problem_.free_turn; }

 private:
  void build_problem();
  // One measurement from a predicted pose: windows, candidates, validation, pose and its
  // checks; sets the counts and reasons of `out` and adds to its stage times. True when the
  // pose is usable. Learns nothing (references change only in track()).
  bool measure(const WindowImage& image, const Eigen::Isometry3d& predicted, FrameReport& out);
  // The first frame (and the first after a reset or a loss) has cue references only from the
  // prediction's projection: a start a centimetre off samples them partly beside the object,
  // and EPIC then prefers the wrong edges (lampshade, seed 13: 7 deg off for 55 frames). A
  // gradient pass, which needs no references, pulls the pose onto the strongest edges; EPIC
  // measures from both starts and the one whose pose keeps the larger share of its features
  // is returned, with the references of that start. When that start is the gradient pass's and
  // no ellipse is seen, its EPIC measurement was settle()'s last and is left in `measured`
  // (reused set): measuring again from the same start with the same references would repeat it
  // exactly, a quarter of a start's cost. `record` says which start was kept and why.
  Eigen::Isometry3d settle(const WindowImage& image, const Eigen::Isometry3d& predicted, StageTimes& times,
                           FrameReport& measured, bool& reused, StartSettle& record);
  void set_mode(TrackMode mode);
  const CadModel* model_;
  Camera camera_;
  ModelTrackerOptions options_;
  Visibility visibility_;
  RimSides rim_sides_;
  LineTracker lines_;
  EllipseTracker ellipses_;
  TopologyValidator validator_;
  PoseEstimator estimator_;
  VisibleModel visible_;
  ObjectRegion region_;  // learnt on the first frame after a start (outline_colours)
  ValidationResult validation_;
  PoseProblem problem_;
  PoseResult pose_;
  std::vector<int> chord_of_circle_;          // per model edge: the circle it is a chord of, or -1
  std::vector<int> line_slot_;                // per model edge: its slot in problem_.lines
  std::vector<unsigned char> kept_last_;      // per model edge: found and kept by the pose last frame
  std::vector<unsigned char> kept_now_;
  bool was_lost_ = false;
  bool settled_ = false;  // references learnt from a tracked frame (false: settle() first)
};

}  // namespace epichead::vision
