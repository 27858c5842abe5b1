#include "epichead/head/backlash_estimate.h"

#include <algorithm>
#include <cmath>

namespace epichead::head {

BacklashEstimator::BacklashEstimator(const BacklashEstimateOptions& options) : options_(options) {
  options_.window = std::clamp(options_.window, 1, kMaxWindow);
  options_.min_samples = std::clamp(options_.min_samples, 1, options_.window);
}

void BacklashEstimator::camera_rate(double joint_rate_radps, double dt_s) {
  if (std::isfinite(joint_rate_radps) && dt_s > 0) camera_rad_ += joint_rate_radps * dt_s;
}

void BacklashEstimator::restart_leg() {
  have_reading_ = false;
  direction_ = 0;
  leg_engaged_ = leg_from_edge_ = pending_ = false;
}

void BacklashEstimator::motor_angle(double t_s, double motor_rad, double body_joint_rate_radps) {
  if (!options_.enabled || !std::isfinite(t_s) || !std::isfinite(motor_rad) || !std::isfinite(body_joint_rate_radps))
    return;
  if (have_reading_ && !(t_s > previous_t_s_)) return;
  if (have_reading_ && t_s - previous_t_s_ > options_.max_reading_gap_s) restart_leg();
  previous_t_s_ = t_s;
  const Reading now{t_s, motor_rad, camera_rad_, body_joint_rate_radps};
  if (!have_reading_) {
    have_reading_ = true;
    extreme_ = now;
    return;
  }
  if (direction_ == 0) {
    // The first leg: whether the output sat on an edge at its start is unknown.
    if (std::abs(motor_rad - extreme_.motor_rad) < options_.reversal_rad) return;
    direction_ = motor_rad > extreme_.motor_rad ? 1 : -1;
    leg_ = extreme_;
    extreme_ = now;
  } else if (direction_ * (motor_rad - extreme_.motor_rad) > 0) {
    extreme_ = now;
  } else if (direction_ * (extreme_.motor_rad - motor_rad) >= options_.reversal_rad) {
    // Turned back at the extreme: the output sat on the edge there if it moved with the motor.
    // A sample still waiting for its confirmation stands: its crossing ended, the motor turned.
    if (pending_) settle_pending(true);
    leg_from_edge_ = leg_engaged_;
    leg_engaged_ = false;
    direction_ = -direction_;
    leg_ = extreme_;
    extreme_ = now;
  }
  follow_crossing(now);
}

void BacklashEstimator::follow_crossing(const Reading& now) {
  // The output's travel the new way, the body's turning taken at its rate at the leg's start,
  // and the motor's travel less it: the band once the output has reached the far edge.
  const double output_rad = direction_ * ((now.camera_rad - leg_.camera_rad) - leg_.body_radps * (now.t_s - leg_.t_s));
  const double band_rad = direction_ * (now.motor_rad - leg_.motor_rad) - output_rad;
  if (pending_) {
    if (band_rad - pending_rad_ > options_.confirm_tolerance_rad) settle_pending(false);
    else if (now.t_s - pending_t_s_ >= options_.confirm_s) settle_pending(true);
    return;
  }
  if (leg_engaged_ || output_rad < options_.engaged_rad) return;
  leg_engaged_ = true;
  if (!leg_from_edge_) return;
  if (now.t_s - leg_.t_s > options_.max_crossing_s || std::abs(leg_.body_radps) > options_.quiet_body_radps ||
      std::abs(now.body_radps) > options_.quiet_body_radps || !(band_rad >= 0) || band_rad > options_.max_rad) {
    ++rejected_;
    return;
  }
  pending_ = true;
  pending_rad_ = band_rad;
  pending_t_s_ = now.t_s;
}

void BacklashEstimator::settle_pending(bool confirmed) {
  pending_ = false;
  if (confirmed) take_sample(pending_rad_);
  else ++rejected_;
}

double BacklashEstimator::band_rad(double calibrated_rad) const {
  if (!options_.enabled || !has_estimate()) return calibrated_rad;
  const double applied = options_.applied_fraction * estimate_rad_;
  return applied >= options_.min_applied_rad ? std::max(calibrated_rad, applied) : calibrated_rad;
}

void BacklashEstimator::take_sample(double band_rad) {
  ++accepted_;
  recent_[static_cast<std::size_t>(next_)] = band_rad;
  next_ = (next_ + 1) % options_.window;
  count_ = std::min(count_ + 1, options_.window);
  if (!has_estimate()) return;
  std::array<double, kMaxWindow> sorted = recent_;
  const auto mid = sorted.begin() + count_ / 2;
  std::nth_element(sorted.begin(), mid, sorted.begin() + count_);
  estimate_rad_ = *mid;
}

}  // namespace epichead::head
