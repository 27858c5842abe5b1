#include "epichead/fusion/learnt_gravity.h"

#include <algorithm>
#include <cmath>

#include "epichead/fusion/nav_state.h"
#include "epichead/geometry/so3.h"

namespace epichead::fusion {

LearntGravity::LearntGravity(const GravityCheckOptions& options) : options_(options) {
  const auto& told = options_.told_down_obj;
  if (told && told->allFinite() && told->norm() > 1e-9) {
    down_obj_ = told->normalized();
    learnt_ = told_ = true;
  }
}

void LearntGravity::learn(double t_s, const Eigen::Vector3d& down_obj, double sigma_rad,
                          const Eigen::Vector3d& gyro_bias_radps, const Eigen::Vector3d& accel_bias_mps2,
                          int applied_in_a_row) {
  if (!options_.enabled || applied_in_a_row < options_.learn_after_applied || !(sigma_rad < options_.learn_sigma_rad) ||
      !down_obj.allFinite() || down_obj.norm() < 1e-9)
    return;
  gyro_bias_radps_ = gyro_bias_radps;
  accel_bias_mps2_ = accel_bias_mps2;
  biases_learnt_ = true;
  if (told_) return;  // the direction is the user's
  const Eigen::Vector3d d = down_obj.normalized();
  if (!learnt_) {
    down_obj_ = d;
    learnt_since_s_ = t_s;
  } else {
    const double a = std::clamp((t_s - learnt_t_s_) / options_.learn_time_s, 0.0, 1.0);
    down_obj_ = ((1 - a) * down_obj_ + a * d).normalized();
  }
  learnt_ = true;
  learnt_t_s_ = t_s;
}

std::optional<double> LearntGravity::tilt_error_rad(const Eigen::Matrix3d& cam_R_obj,
                                                    const std::optional<Eigen::Vector3d>& down_cam) const {
  if (!options_.enabled || !learnt_ || !down_cam) return std::nullopt;
  const auto angle = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); };
  if (const auto& axis = options_.free_turn_axis_obj) {
    // The smallest tilt error over every turn about the axis.
    return std::abs(angle(cam_R_obj * *axis, *down_cam) - angle(*axis, down_obj_));
  }
  return angle(cam_R_obj * down_obj_, *down_cam);
}

Eigen::Vector3d LearntGravity::down_obj_toward(const Eigen::Vector3d& measured_down_obj) const {
  const auto& axis = options_.free_turn_axis_obj;
  if (!axis) return down_obj_;
  const Eigen::Vector3d across = measured_down_obj - measured_down_obj.dot(*axis) * *axis;
  if (!(across.norm() > 1e-6)) return down_obj_;
  const double cos_a = std::clamp(down_obj_.dot(*axis), -1.0, 1.0);
  return cos_a * *axis + std::sqrt(1 - cos_a * cos_a) * across.normalized();
}

void LearntGravity::note_verdict(double t_s, bool contradicts) {
  if (!contradicts) {
    contradicted_since_s_ = -1;
    return;
  }
  if (contradicted_since_s_ < 0) contradicted_since_s_ = t_s;
  if (t_s - contradicted_since_s_ >= options_.forget_after_s) {
    learnt_ = told_ = false;
    contradicted_since_s_ = -1;
    ++forgotten_;
  }
}

void LearntGravity::forget_learnt() {
  if (!learnt_ || told_) return;
  learnt_ = false;
  contradicted_since_s_ = -1;
  ++forgotten_;
}

std::optional<MeanForce> mean_specific_force(const StateHistory& history, double t_s, double window_s, double min_window_s,
                                            double dropout_gap_s, const Eigen::Vector3d& gyro_bias_radps,
                                            const Eigen::Vector3d& accel_bias_mps2) {
  const std::optional<std::uint64_t> k = history.find_at_or_before(t_s);
  if (!k) return std::nullopt;
  const double newest_t = history.at(*k).sample.t_s;
  if (t_s - newest_t > dropout_gap_s) return std::nullopt;  // the exposure is inside a gap
  // imu_R: the IMU frame at the newest sample <- the IMU frame at the sample being added. From a
  // sample to the next the body turns by exp(w dt), so a reading is brought forward by its transpose.
  Eigen::Matrix3d imu_R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d sum = history.at(*k).sample.accel_mps2 - accel_bias_mps2;
  MeanForce out;
  out.newest_seq = out.oldest_seq = *k;
  for (std::uint64_t seq = *k; seq > history.oldest_seq(); --seq) {
    const ImuSample& later = history.at(seq).sample;
    const ImuSample& s = history.at(seq - 1).sample;
    const double dt = later.t_s - s.t_s;
    if (dt > dropout_gap_s || newest_t - s.t_s > window_s) break;
    imu_R = imu_R * geometry::so3_exp((s.gyro_radps - gyro_bias_radps) * dt).transpose();
    sum += imu_R * (s.accel_mps2 - accel_bias_mps2);
    out.oldest_seq = seq - 1;
  }
  if (newest_t - history.at(out.oldest_seq).sample.t_s < min_window_s) return std::nullopt;
  out.mean_imu_mps2 = sum / static_cast<double>(out.newest_seq - out.oldest_seq + 1);
  if (!out.mean_imu_mps2.allFinite()) return std::nullopt;
  return out;
}

std::optional<Eigen::Vector3d> down_from(const MeanForce& force, const Eigen::Vector3d& mean_accel_imu_mps2) {
  // Specific force = acceleration - gravity: gravity = mean acceleration - mean force.
  const Eigen::Vector3d g = mean_accel_imu_mps2 - force.mean_imu_mps2;
  if (!g.allFinite() || std::abs(g.norm() - standard_gravity_mps2) > 0.3 * standard_gravity_mps2) return std::nullopt;
  return g.normalized();
}

std::optional<Eigen::Vector3d> measured_down_imu(const StateHistory& history, double t_s, double window_s,
                                                 double min_window_s, double dropout_gap_s,
                                                 const Eigen::Vector3d& gyro_bias_radps,
                                                 const Eigen::Vector3d& accel_bias_mps2) {
  const auto force = mean_specific_force(history, t_s, window_s, min_window_s, dropout_gap_s, gyro_bias_radps, accel_bias_mps2);
  if (!force) return std::nullopt;
  return down_from(*force);
}

}  // namespace epichead::fusion
