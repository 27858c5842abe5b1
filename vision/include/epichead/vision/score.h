#pragma once
// Scoring of estimated poses against ground truth: per-frame rotation, translation and
// reprojection errors, success under the 5 cm / 5 degree criterion, and a summary.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/stamped_pose.h"

namespace epichead::vision {

struct ScoreCriterion {
  double max_translation_m = 0.05;
  double max_rotation_deg = 5.0;
};

struct FrameScore {
  int frame = 0;
  bool present = false;   // the frame has an estimate
  bool success = false;   // present and within the criterion
  double rotation_deg = 0, translation_mm = 0, reprojection_px = 0;  // NaN when absent
};

struct ErrorStats { double mean = 0, median = 0, p95 = 0; };

struct ScoreSummary {
  int frames = 0, present = 0, succeeded = 0;
  double success_rate = 0;  // succeeded / frames
  int losses = 0;           // runs of consecutive failed frames
  ErrorStats rotation_deg, translation_mm, reprojection_px;  // over present frames
  std::vector<FrameScore> per_frame;
};

// Scores `estimates` against `ground_truth` frame by frame (matched on the frame column).
// A ground-truth frame without an estimate fails. With sym_axis_obj (a unit axis through the
// object origin), the turn about it that makes the estimate closest to the truth is removed
// first, since it is unobservable for a body of revolution.
ScoreSummary score_poses(const std::vector<StampedPose>& ground_truth,
                         const std::vector<StampedPose>& estimates, const Camera& camera,
                         const CadModel& model,
                         const std::optional<Eigen::Vector3d>& sym_axis_obj = std::nullopt,
                         const ScoreCriterion& criterion = {});

}  // namespace epichead::vision
