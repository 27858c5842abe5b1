#pragma once
// The detector's state, shared by the two files that implement it: detector_templates.cpp
// (the view grid, rendering, the cache, create()) and detector.cpp (matching, candidates,
// refinement and verification, detect()).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/rgbd/linemod.hpp>

#include "edge_support.h"
#include "epichead/vision/detector.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/revolution_axis.h"
#include "template_cache.h"

namespace epichead::vision {

namespace detail {
using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
// LINE-2D's class of a view and turn: its templates are the distances.
inline std::string class_id(int view, int roll) { return "v" + std::to_string(view) + "r" + std::to_string(roll); }
}  // namespace detail

struct Detector::Impl {
  Impl(const CadModel& m, const Camera& c, const DetectorOptions& o, const ModelTrackerOptions& t)
      : model_storage(m), model(&model_storage), camera(c), options(o), pull(model_storage, c, wide(t)),
        tracker(model_storage, c, without_outline_colours(t)), visibility(model_storage, c, whole_circles(t.visibility)),
        symmetries(model_symmetries(m)) {
    if (const auto axis = find_revolution_axis(m)) free_axis_obj = axis->direction_obj.normalized();
  }

  // A hypothesis can be off by more than the outline colours' margins, and then draws the
  // background into the object's histogram: on the real tea box video the colours pulled the
  // right hypothesis off the box and a wrong one won. The detector's trackers do without them.
  static ModelTrackerOptions without_outline_colours(ModelTrackerOptions t) {
    t.outline_colours = false;
    return t;
  }

  // The pull's windows are twice as wide as tracking's: a template's pose can be off by more
  // than a frame's motion. For the same reason its rims may change size and openness freely:
  // the limits that refuse another contour in tracking (a prediction a few percent off) would
  // refuse the rim itself from a template half a grid step away in distance and view.
  static ModelTrackerOptions wide(ModelTrackerOptions t) {
    t = without_outline_colours(t);
    t.lines.window.width_px = std::min(kMaxWindowWidth, 2 * t.lines.window.width_px);
    t.max_jump_px = 2 * t.max_jump_px;
    t.ellipses.max_size_change = std::numeric_limits<double>::infinity();
    t.ellipses.max_openness_change = std::numeric_limits<double>::infinity();
    return t;
  }

  // The quick scores and the verification sample whole ellipses: no need to clip them.
  static VisibilityOptions whole_circles(VisibilityOptions v) {
    v.clip_circles = false;
    return v;
  }

  // The detector keeps its own copy of the model: the trackers and visibility refer to it, and
  // the caller's may go (the onboard loop takes the detector over).
  CadModel model_storage;
  const CadModel* model;
  Camera camera;
  DetectorOptions options;
  // A template's pose is up to half a grid step off in view, turn and distance: a tracker with
  // wide windows pulls it in first; the caller's tracker then measures it as tracking will.
  ModelTracker pull;
  ModelTracker tracker;
  Visibility visibility;
  VisibleModel visible;
  WindowImage window_image;
  detail::EdgeGradients gradients;
  cv::Mat colour;  // the frame, BGR, unpadded (colour_continuation)
  cv::Ptr<cv::linemod::Detector> line2d;
  std::vector<Eigen::Vector3d> views;
  std::vector<double> rolls_rad;
  std::vector<double> distances_m;
  std::vector<detail::TemplateSpec> specs;
  std::map<std::string, std::vector<int>> class_specs;  // class id -> spec index per template id
  Eigen::Vector3d centre_obj = Eigen::Vector3d::Zero();
  double radius_m = 0;
  std::vector<Eigen::Vector3d> outline_obj;  // model points whose projections stand for a pose's outline
  std::vector<Eigen::Vector2d> scratch_outline;
  // The model's own symmetries (model_symmetry.h): poses that differ by one draw the same
  // outline, so the search cannot choose among them; the prior can (choose_symmetric).
  std::vector<Eigen::Isometry3d> symmetries;
  // A body of revolution's axis (revolution_axis.h): a turn about it is no outline's to tell.
  std::optional<Eigen::Vector3d> free_axis_obj;

  void project_outline(const Eigen::Isometry3d& T, std::vector<Eigen::Vector2d>& px) const {
    px.clear();
    for (const auto& p : outline_obj) {
      const Eigen::Vector3d q = T * p;
      if (q.z() > 1e-6) px.push_back(camera.project(q));
    }
  }
  std::string cache_path;
  bool from_cache = false;
  double build_s = 0;
  std::vector<std::string> warnings;

  std::uint64_t key() const;
  // LINE-2D on colour gradients (a drawing of white edges gives the same orientations as a
  // grey frame's gradients, and the matcher takes BGR): T = 5 px at full resolution, 8 px at half.
  cv::Ptr<cv::linemod::Detector> make_matcher() const {
    std::vector<cv::Ptr<cv::linemod::Modality>> modalities{
        cv::makePtr<cv::linemod::ColorGradient>(10.0f, static_cast<std::size_t>(options.features_per_template), 55.0f)};
    return cv::makePtr<cv::linemod::Detector>(modalities, std::vector<int>{5, 8});
  }
  void grids();
  std::vector<detail::TemplateRecord> render(const Progress& progress);
  void load(const std::vector<detail::TemplateRecord>& records);
  Eigen::Isometry3d template_pose(int view, int roll, double distance_m) const;
  std::vector<std::string> classes_for(const DetectionPrior& prior) const;
  std::vector<Eigen::Isometry3d> hypotheses(const std::vector<cv::linemod::Match>& matches, const DetectionPrior& prior,
                                            std::vector<float>& similarity);
  DetectionHypothesis refine(const Eigen::Isometry3d& start, float similarity);
  // Support, score and outline length of h's pose on the current frame (gradients).
  // whole_object: a pose with part of the model outside the image scores 0 (detections).
  DetectionHypothesis measure(DetectionHypothesis h, bool whole_object = true);
  // Takes a frame: the matcher's BGR (padded), the grey gradients and the tracker's image.
  std::expected<cv::Mat, std::string> take_frame(const cv::Mat& frame);
  // Among h's pose and its symmetric equivalents, the one nearest the prior: the turn closest
  // to orient_like's or the predicted pose's, or else the one that puts the object's up nearest
  // the world's.
  // A can found again after a cover is otherwise as likely upside down (issue 19).
  void choose_symmetric(DetectionHypothesis& h, const DetectionPrior& prior) const;
  bool verified(const DetectionHypothesis& h) const { return failed_detection_tests(h, options) == 0; }
  // With the prior's orientation: how far cam_R_obj is turned from it (symmetric_turn_rad), deg.
  double turn_off_deg(const Eigen::Matrix3d& cam_R_obj, const DetectionPrior& prior) const {
    return symmetric_turn_rad(cam_R_obj, *prior.cam_R_obj, symmetries, free_axis_obj) * 180.0 / M_PI;
  }
  // Whether a pose turned cam_R_obj may be the prior's, `slack_deg` beyond its tolerance (true
  // without an orientation in the prior).
  bool turned_near(const Eigen::Matrix3d& cam_R_obj, const DetectionPrior& prior, double slack_deg) const {
    return !prior.cam_R_obj || turn_off_deg(cam_R_obj, prior) <= prior.turn_tolerance_deg + slack_deg;
  }
  // The farthest a pose's turn can be from its nearest template's: half the view grid's spacing
  // (an icosahedron's 63 deg edge halved per subdivision) and half the in-plane step.
  double template_turn_slack_deg() const {
    return 0.5 * (63.4 / std::pow(2.0, options.view_subdivisions) + options.in_plane_step_deg);
  }
};


}  // namespace epichead::vision
