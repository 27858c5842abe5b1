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
  direction_ = reference_direction_ = 0;
  leg_engaged_ = pending_ = false;
}

void BacklashEstimator::motor_angle(double t_s, double motor_rad) {
  if (!options_.enabled || !std::isfinite(t_s) || !std::isfinite(motor_rad)) return;
  const double dt = t_s - previous_.t_s;
  if (have_reading_ && !(dt > 0)) return;
  if (have_reading_ && dt > options_.max_reading_gap_s) restart_leg();
  if (!have_reading_) {
    have_reading_ = true;
    body_radps_ = 0;
    previous_ = extreme_ = {t_s, motor_rad, camera_rad_, 0};
    return;
  }
  // The body's rate about the joint over the interval: the camera's less the output's (the
  // motor's while they move together, none while the output rests in the band).
  const double output_radps = leg_engaged_ ? (motor_rad - previous_.motor_rad) / dt : 0;
  const double raw_body_radps = (camera_rad_ - previous_.camera_rad) / dt - output_radps;
  body_before_radps_ = body_radps_;
  body_radps_ += dt / (options_.body_filter_s + dt) * (raw_body_radps - body_radps_);
  Reading now{t_s, motor_rad, camera_rad_, body_radps_};
  previous_ = now;
  if (direction_ == 0) {
    if (std::abs(motor_rad - extreme_.motor_rad) < options_.reversal_rad) return;
    direction_ = motor_rad > extreme_.motor_rad ? 1 : -1;
    leg_ = extreme_;
    extreme_ = now;
  } else if (direction_ * (motor_rad - extreme_.motor_rad) > 0) {
    extreme_ = now;
  } else if (direction_ * (extreme_.motor_rad - motor_rad) >= options_.reversal_rad) {
    // Turned back at the extreme. A sample still waiting for its confirmation stands: its
    // crossing ended and the output moved with the motor until it turned.
    if (pending_) settle_pending(true);
    if (leg_engaged_) {  // the output sits on the edge the motor left here
      reference_ = extreme_;
      reference_direction_ = direction_;
    }
    leg_engaged_ = false;
    direction_ = -direction_;
    leg_ = extreme_;
    extreme_ = now;
  }
  follow_crossing(now);
}

void BacklashEstimator::follow_crossing(Reading& now) {
  // The output's travel this leg's way since it last moved (from the reference, or without one
  // from the leg's start), the body's turning taken at its rate then.
  const Reading& from = reference_direction_ != 0 ? reference_ : leg_;
  const double output_rad = direction_ * ((now.camera_rad - from.camera_rad) - from.body_radps * (now.t_s - from.t_s));
  // The motor's travel from the reference less the output's: the band once the output moves.
  const double band_rad = direction_ * (now.motor_rad - from.motor_rad) - output_rad;
  if (pending_) {
    if (band_rad - pending_rad_ > options_.confirm_tolerance_rad) settle_pending(false);
    else if (now.t_s - pending_t_s_ >= options_.confirm_s) settle_pending(true);
    return;
  }
  if (leg_engaged_ || output_rad < options_.engaged_rad) return;
  leg_engaged_ = true;
  // The output started to move within the last interval, which took its turning for the body's:
  // the body's rate stays as it was before it.
  body_radps_ = now.body_radps = body_before_radps_;
  previous_.body_radps = body_radps_;
  if (extreme_.t_s == now.t_s) extreme_.body_radps = body_radps_;
  // Moving on the way it last went, or no reference: no band crossed.
  if (reference_direction_ != -direction_) return;
  if (now.t_s - from.t_s > options_.max_crossing_s || std::abs(from.body_radps) > options_.quiet_body_radps ||
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
