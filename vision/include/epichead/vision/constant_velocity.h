#pragma once
// The vision poses extrapolated alone: the last relative motion between good poses, scaled to the
// elapsed time and applied on the left (where camera motion acts on cam_T_obj). `track` without an
// IMU predicts by it; with the IMU, `track` and the onboard loop give it to the tracker as the
// second opinion (ModelTracker::track's fallback) for frames where the filter's prediction has
// left the object. Plain values, no allocation.
#include <Eigen/Geometry>

#include "epichead/vision/model_tracker.h"

namespace epichead::vision {

class ConstantVelocity {
 public:
  // Starts from `cam_T_obj` at t_s, at rest.
  ConstantVelocity(double t_s, const Eigen::Isometry3d& cam_T_obj) { restart(t_s, cam_T_obj); }
  // A new start (a detection, a given pose): at rest there.
  void restart(double t_s, const Eigen::Isometry3d& cam_T_obj);
  // The pose extrapolated to t_s (the last pose while no motion is known).
  Eigen::Isometry3d predict(double t_s) const;
  // A frame's result at its exposure t_s: a tracked pose extends the motion; a degraded one is
  // where the next frame starts, without motion; a lost frame goes back to the last tracked pose.
  void observe(double t_s, TrackStatus status, const Eigen::Isometry3d& cam_T_obj);

 private:
  Eigen::Isometry3d last_, last_tracked_, prev_;
  double last_t_s_ = 0, prev_t_s_ = 0;
  bool have_motion_ = false;
};

}  // namespace epichead::vision
