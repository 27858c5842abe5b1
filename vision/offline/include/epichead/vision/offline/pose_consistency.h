#pragma once
// Is a tracker's covariance honest? The normalised estimation error squared (NEES) of each
// scored frame, e' C^-1 e with e the pose error against the truth (FrameScore::error_twist) and C
// the covariance the tracker gave (vision_covariance.csv): with honest covariances it follows a
// chi-square distribution with as many degrees of freedom as the error has (6; 5 when a body of
// revolution's turn is taken out before scoring). Only frames within the 5 cm / 5 deg criterion
// count: a wrong lock is a failure of tracking, scored as such, not of its covariance.
#include <vector>

#include "epichead/vision/offline/pose_covariance_csv.h"
#include "epichead/vision/offline/score.h"

namespace epichead::vision {

struct PoseConsistency {
  int dof = 6;
  int count = 0;               // frames with a covariance, an estimate and success
  double mean = 0, median = 0;  // NaN when count is 0
  double below_2_5pct = 0;     // fraction below chi-square's 2.5 % quantile: covariance too large
  double above_97_5pct = 0;    // fraction above its 97.5 % quantile: covariance too small
  double within_95pct = 0;     // between the two: 0.95 when honest
  // The factor the covariances would need to be scaled by for a mean NEES of dof.
  double scale_for_mean = 0;
  // Each counted frame's NEES, in frame order (score --per-frame writes them).
  struct FrameNees {
    int frame = 0;
    double nees = 0;
  };
  std::vector<FrameNees> per_frame;
};

// 6 degrees of freedom, or 5 when the summary was scored with a symmetry axis (score_poses'
// sym_axis_obj): then the error and the covariance are both taken on the five directions
// orthogonal to the turn about the axis. Frames are matched on their number.
PoseConsistency pose_consistency(const ScoreSummary& summary, const std::vector<StampedCovariance>& covariances);

}  // namespace epichead::vision
