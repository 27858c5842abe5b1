#pragma once
// Scoring of estimated poses against ground truth: per-frame rotation, translation and
// reprojection errors, success under the 5 cm / 5 degree criterion, and a summary.
#include <expected>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/offline/stamped_pose.h"

namespace epichead::vision {

struct ScoreCriterion {
  double max_translation_m = 0.05;
  double max_rotation_deg = 5.0;
  // The accuracy criterion beside it: right by 5 cm / 5 deg can still sit on a printed border
  // a few millimetres off the real edge.
  double tight_translation_m = 0.02;
  double tight_rotation_deg = 2.0;
};

struct FrameScore {
  int frame = 0;
  bool present = false;   // the frame has an estimate
  bool success = false;   // present and within the criterion
  bool success_tight = false;  // present and within the tight criterion
  double rotation_deg = 0, translation_mm = 0, reprojection_px = 0;  // NaN when absent
  // The error as a left perturbation (geometry/pose_covariance.h): truth = se3_exp(error_twist) *
  // estimate, after the symmetry turns are taken out; NaN when absent.
  Eigen::Matrix<double, 6, 1> error_twist = Eigen::Matrix<double, 6, 1>::Constant(std::numeric_limits<double>::quiet_NaN());
  // With a symmetry axis: the direction, in the same coordinates, of a turn about that axis at the
  // estimate (unit rotation part). The error has no component the scoring can see along it, so a
  // covariance check leaves it out. Zero without an axis.
  Eigen::Matrix<double, 6, 1> axis_twist = Eigen::Matrix<double, 6, 1>::Zero();
};

struct ErrorStats { double mean = 0, median = 0, p95 = 0; };

struct ScoreSummary {
  int frames = 0, present = 0, succeeded = 0;
  double success_rate = 0;  // succeeded / frames
  int succeeded_tight = 0;
  double success_rate_tight = 0;  // succeeded_tight / frames
  int losses = 0;           // runs of consecutive failed frames
  ErrorStats rotation_deg, translation_mm, reprojection_px;  // over present frames
  std::vector<FrameScore> per_frame;
};

// R_est turned about `axis` (unit, object frame) by the angle that brings it closest to R_gt:
// for a body of revolution, whose turn about its axis edges cannot show.
Eigen::Matrix3d remove_turn(const Eigen::Matrix3d& R_gt, const Eigen::Matrix3d& R_est, const Eigen::Vector3d& axis);

// Scores `estimates` against `ground_truth` frame by frame (matched on the frame column).
// A ground-truth frame without an estimate, or whose estimate has status "lost", fails. With sym_axis_obj (a unit axis through the
// object origin), the turn about it that makes the estimate closest to the truth is removed
// first, since it is unobservable for a body of revolution. With symmetries_obj (object-frame
// turns that leave the model's look unchanged, model_symmetry.h), the estimate composed with
// whichever of them (or none) brings it closest to the truth is scored.
ScoreSummary score_poses(const std::vector<StampedPose>& ground_truth,
                         const std::vector<StampedPose>& estimates, const Camera& camera,
                         const CadModel& model,
                         const std::optional<Eigen::Vector3d>& sym_axis_obj = std::nullopt,
                         const ScoreCriterion& criterion = {},
                         const std::vector<Eigen::Isometry3d>& symmetries_obj = {});

// A model point read by hand in an image (real video has no ground truth): X Y Z u v per line.
struct CornerObservation {
  Eigen::Vector3d p_obj = Eigen::Vector3d::Zero();
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
};
struct CornerError { double rms_px = 0, max_px = 0; };
// Reads "X Y Z u v" lines ('#' starts a comment); errors say file:line.
std::expected<std::vector<CornerObservation>, std::string> read_corners(const std::string& path);
// Distance of the projected model points from the hand-read pixels at a pose.
CornerError corner_error(const std::vector<CornerObservation>& corners, const Eigen::Isometry3d& cam_T_obj,
                         const Camera& camera);

}  // namespace epichead::vision
