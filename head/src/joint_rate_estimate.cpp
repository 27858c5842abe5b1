#include "epichead/head/joint_rate_estimate.h"

#include <algorithm>
#include <cmath>

namespace epichead::head {

void JointRateEstimate::sent(double t_s, const Eigen::Vector2d& rates_radps, const Eigen::Vector2d& output_rates_radps) {
  const double act_t_s = t_s + options_.command_delay_s;
  // Where the modelled joint rates stand when this command starts to act.
  Eigen::Vector2d model = rates_radps, output_model = output_rates_radps;
  if (!sent_.empty()) {
    const Sent& prev = sent_.newest();
    if (act_t_s < prev.t_s) return;
    if (options_.motor_lag_s > 0) {
      model = model_at(prev, act_t_s);
      output_model = output_model_at(prev, act_t_s);
    }
  } else if (options_.motor_lag_s > 0) {
    model = output_model = measured_;  // the first command starts from the joints' measured motion
  }
  sent_.push_overwrite({act_t_s, rates_radps, model, output_rates_radps, output_model});
}

const JointRateEstimate::Sent* JointRateEstimate::in_force(double t_s) const {
  for (std::size_t i = sent_.size(); i-- > 0;) {  // newest first
    const Sent& s = sent_[i];
    if (s.t_s <= t_s) return t_s - s.t_s <= options_.max_command_age_s ? &s : nullptr;
  }
  return nullptr;
}

Eigen::Vector2d JointRateEstimate::lagged(const Eigen::Vector2d& command, const Eigen::Vector2d& model, double from_t_s,
                                          double t_s) const {
  if (!(options_.motor_lag_s > 0)) return command;
  const double decay = std::exp(-std::max(0.0, t_s - from_t_s) / options_.motor_lag_s);
  return command + decay * (model - command);
}

void JointRateEstimate::measured(double t_s, const Eigen::Vector2d& rates_radps) {
  if (const Sent* s = in_force(t_s)) {
    const double dt = have_measured_ ? std::max(0.0, t_s - measured_t_s_) : 0.0;
    const double k = std::min(1.0, dt / options_.correction_time_constant_s);
    correction_ += k * (rates_radps - model_at(*s, t_s) - correction_);
  } else {
    correction_.setZero();
  }
  have_measured_ = true;
  measured_t_s_ = t_s;
  measured_ = rates_radps;
}

Eigen::Vector2d JointRateEstimate::at(double t_s) const {
  if (const Sent* s = in_force(t_s)) return output_model_at(*s, t_s) + correction_;
  return measured_;
}

void JointRateEstimate::reset() {
  sent_.clear();
  correction_.setZero();
}

}  // namespace epichead::head
