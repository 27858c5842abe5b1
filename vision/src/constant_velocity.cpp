#include "epichead/vision/constant_velocity.h"

namespace epichead::vision {

void ConstantVelocity::restart(double t_s, const Eigen::Isometry3d& cam_T_obj) {
  last_ = last_tracked_ = prev_ = cam_T_obj;
  last_t_s_ = prev_t_s_ = t_s;
  have_motion_ = false;
}

Eigen::Isometry3d ConstantVelocity::predict(double t_s) const {
  if (!have_motion_ || !(last_t_s_ > prev_t_s_)) return last_;
  const double s = (t_s - last_t_s_) / (last_t_s_ - prev_t_s_);
  const Eigen::Isometry3d delta = last_ * prev_.inverse();
  const Eigen::AngleAxisd rot(delta.rotation());
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  step.linear() = Eigen::AngleAxisd(s * rot.angle(), rot.axis()).toRotationMatrix();
  step.translation() = s * delta.translation();
  return step * last_;
}

void ConstantVelocity::observe(double t_s, TrackStatus status, const Eigen::Isometry3d& cam_T_obj) {
  if (status == TrackStatus::Lost) {
    // Keep trying from the last pose the image fully supported (a degraded pose before the loss
    // may be where it went wrong), without extrapolating.
    have_motion_ = false;
    last_ = last_tracked_;
    return;
  }
  if (status == TrackStatus::Tracked) last_tracked_ = cam_T_obj;
  if (status == TrackStatus::Degraded) {
    // A doubtful pose (high residual, few inliers) is where the next frame starts, but no motion
    // is extrapolated from it: one pose a few degrees off, taken as a velocity, throws the next
    // frame's windows off the object, and each frame after it further (mockup_walk, seed 11: from
    // 0.4 to 32 deg in three frames during a step).
    last_ = cam_T_obj;
    last_t_s_ = t_s;
    have_motion_ = false;
    return;
  }
  prev_ = last_;
  prev_t_s_ = last_t_s_;
  have_motion_ = true;
  last_ = cam_T_obj;
  last_t_s_ = t_s;
}

}  // namespace epichead::vision
