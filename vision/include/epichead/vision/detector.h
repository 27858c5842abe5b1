#pragma once
// Detection: the pose of the model in one frame from the CAD model and the camera alone, with
// no starting pose and no training images. Templates of the model's visible edges are rendered
// over a view sphere, in-plane turns and a distance range and matched by gradient orientation
// (OpenCV contrib's LINE-2D, cv::linemod); every hypothesis is then refined by the tracker's
// own machinery (settling pass, EPIC, robust pose) and verified by how much of the projected
// model an image edge of the right orientation supports. The best verified pose wins.
//
// Templates depend only on the model, the camera and the options: building them takes seconds
// to a minute, so they are cached on disk (template_cache.h) and read back in well under a second.
#include <cstdint>
#include <expected>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/model_tracker.h"

namespace epichead::vision {

struct DetectorOptions {
  // Views: the vertices of an icosahedron subdivided this many times (2: 162 directions,
  // about 17 deg apart; 3: 642, about 8.5 deg).
  int view_subdivisions = 2;
  double in_plane_step_deg = 15.0;  // turns about the line of sight
  // Distance range of the object's centre, m; 0 = from the model's size and the image: the
  // diameter of the model's bounding sphere spans from min_span to max_span of the image's
  // shorter side (the sphere is larger than what a view shows, hence above 1; templates of
  // views that do not fit in the image are not made).
  double min_distance_m = 0, max_distance_m = 0;
  double min_span = 0.3, max_span = 1.2;
  double distance_ratio = 1.2;  // between neighbouring template distances
  int features_per_template = 63;
  // With a known gravity direction: only views whose object up lies within this of the
  // camera's up are matched (gravity from the accelerometer, the object's up from the model).
  double up_tolerance_deg = 25.0;
  // Hypotheses: of the LINE-2D matches at or above min_similarity (percent), the best
  // max_candidates (shared out over the distances) are scored by the edge support of their
  // outline within candidate_radius_px at the template's pose; the best max_hypotheses of
  // those, without duplicates and again shared out over the distances (what one distance
  // leaves goes to the best of the rest), are refined and verified.
  float min_similarity = 75.0f;
  int max_candidates = 2000;
  double candidate_radius_px = 4.0;
  int max_hypotheses = 48;
  double duplicate_px = 8.0;  // hypotheses whose projected model points lie this close are one
  int refine_passes = 8;  // tracking steps on the frame from each hypothesis
  // A detection is reported found when at least this share of the projected model's edge
  // samples has an image edge of its orientation within support_radius_px.
  double min_support = 0.55;
  double support_radius_px = 2.0;
  // ... and the supported part of the outline is at least this long: a short outline (a far
  // box seen face-on is a rectangle) is matched by printed rectangles in clutter as readily as
  // by the object (late_entry: 0.81 of a 300 px outline on a poster).
  double min_supported_px = 400.0;
  // ... and the outline does not run on past the object: across the silhouette's lines past
  // their ends the colours differ at most this much, relative to across the lines along the
  // object (DetectionHypothesis::colour_continuation). A wire-frame laid on a building's facade
  // or windows finds its lines running on; an object in front of its background does not.
  // A test of the best hypothesis only: passing over it to the next one made wrong poses found
  // where none was before (docs/detection.md).
  double max_colour_continuation = 0.8;
  // ... and the outline is not made of a few supported lines beside unsupported ones: at most
  // this share of it (on edges long enough to judge alone) may lie on edges that an image edge
  // supports on less than a quarter of their length. The object's own outline has its edges
  // seen (at most 0.21 on development seeds: the mockup's many small edges); a box made of
  // other objects' lines often has not (the wrong poses found there: up to 0.39). 1 turns the
  // test off.
  double max_unsupported_edge_share = 0.25;
};

// A pose found in one frame.
struct DetectionHypothesis {
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();  // after refinement
  Eigen::Isometry3d start_cam_T_obj = Eigen::Isometry3d::Identity();  // the template's pose it started from
  float similarity = 0;   // LINE-2D's, percent
  double support = 0;     // share of projected edge samples with an image edge (0..1)
  // What ranks hypotheses: support x supported samples. At the same share the pose that
  // explains more outline wins, so a small outline matched on printed texture or clutter
  // loses against the whole object.
  double score = 0;
  double supported_px = 0;  // length of the outline an image edge supports
  // How much the colours across the silhouette's lines still differ past the object's corners,
  // relative to along the object (edge_support.h, colour_continuation; about 0 for an object
  // in front of its background, near 1 when the outline lies on lines that run on).
  double colour_continuation = 0;
  // Of the outline on edges long enough to judge alone (24 px), the share on edges an image
  // edge supports on less than a quarter of their length, and the lowest support of one.
  double unsupported_edge_share = 0;
  double weakest_edge_support = 1;
  // With DetectionPrior::cam_R_obj: how far the pose is turned from it (symmetric_turn_rad), deg;
  // NaN without.
  double turn_off_deg = std::numeric_limits<double>::quiet_NaN();
  TrackStatus status = TrackStatus::Lost;  // of the last refinement step
};

// The verification's tests (DetectorOptions) a hypothesis fails, as bits; none: it is found.
enum DetectionTest : unsigned {
  kTooLittleSupport = 1u << 0,  // support below min_support (0 also when part of the model is outside the image)
  kTooShortOutline = 1u << 1,   // supported_px below min_supported_px
  kOutlineRunsOn = 1u << 2,     // colour_continuation above max_colour_continuation
  kUnsupportedEdges = 1u << 3,  // unsupported_edge_share above max_unsupported_edge_share
};
unsigned failed_detection_tests(const DetectionHypothesis& h, const DetectorOptions& options);

struct DetectionResult {
  bool found = false;
  DetectionHypothesis best;
  int templates_matched = 0;   // templates the gravity filter left
  int matches = 0;             // LINE-2D matches above min_similarity
  std::vector<DetectionHypothesis> hypotheses;  // every refined hypothesis, best score first
  double match_ms = 0, refine_ms = 0;
};

// Where a detection search looks: everywhere, or near a predicted pose (re-acquisition).
struct DetectionPrior {
  std::optional<Eigen::Vector3d> up_cam;  // the world's up in the camera frame (unit)
  std::optional<Eigen::Vector3d> up_obj;  // the object's up in its own frame (unit)
  // Refined and verified first (the tracker's last or predicted pose): when it is found there,
  // the global search is skipped.
  std::optional<Eigen::Isometry3d> near_cam_T_obj;
  // Poses that differ by one of the model's symmetries draw the same outline (a can upside
  // down): the found pose is reported as the one whose turn is nearest this, or near_cam_T_obj,
  // or else the one that puts up_obj nearest up_cam. Unlike near_cam_T_obj it does not narrow
  // the search (a recheck of the tracked pose).
  std::optional<Eigen::Isometry3d> orient_like;
  // The object's orientation in the camera frame, known within turn_tolerance_deg (the gyro
  // carried it across a loss, fusion/carried_orientation.h): only templates turned near it are
  // matched, and a pose turned farther (as far as the model's symmetries and a body of
  // revolution's free turn let any outline tell) is not found. Clutter's outlines, turned any way,
  // then rarely pass (late_entry: 16-105 deg off, on the wall beside the package).
  std::optional<Eigen::Matrix3d> cam_R_obj;
  double turn_tolerance_deg = 0;
};

class Detector {
 public:
  // Progress while building templates: done and total template count.
  using Progress = std::function<void(int done, int total)>;
  // The detector keeps a copy of the model. Reads the templates from `cache_dir` when a cache for this model, camera and options is
  // there, else renders them (reporting progress) and writes the cache. An empty cache_dir
  // neither reads nor writes. A cache that cannot be read is rebuilt, with a warning in
  // warnings(); one that cannot be written is a warning too.
  static std::expected<std::unique_ptr<Detector>, std::string> create(const CadModel& model, const Camera& camera,
                                                                      const DetectorOptions& options,
                                                                      const ModelTrackerOptions& tracking,
                                                                      const std::string& cache_dir,
                                                                      const Progress& progress = {});
  ~Detector();

  // Finds the model in `frame` (8-bit grey or BGR, the camera's size).
  std::expected<DetectionResult, std::string> detect(const cv::Mat& frame, const DetectionPrior& prior = {});

  // The verification of one pose as it is (no search, no refinement): support, score and
  // outline length, as detect() gives its hypotheses, over the part of the model in the image.
  // For comparing the tracked pose with a detection on the same frame.
  std::expected<DetectionHypothesis, std::string> verify(const cv::Mat& frame, const Eigen::Isometry3d& cam_T_obj);

  int template_count() const;
  bool loaded_from_cache() const;
  const std::string& cache_path() const;
  double build_s() const;  // time spent building or reading the templates
  const std::vector<std::string>& warnings() const;

 private:
  struct Impl;
  explicit Detector(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The default directory of template caches: $EPICHEAD_CACHE_DIR, else $XDG_CACHE_HOME/epichead,
// else ~/.cache/epichead; empty when none can be formed.
std::string default_template_cache_dir();

}  // namespace epichead::vision
