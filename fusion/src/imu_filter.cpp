#include "epichead/fusion/imu_filter.h"

#include <algorithm>
#include <cmath>

#include "epichead/fusion/free_direction.h"
#include "epichead/fusion/imu_propagation.h"
#include "epichead/geometry/pose_covariance.h"
#include "epichead/geometry/se3.h"

namespace epichead::fusion {
namespace {

std::size_t history_capacity(const PredictorOptions& o) {
  if (o.mode != PredictorMode::ImuAided) return 2;  // unused
  // 10 % and a few samples of headroom for clock jitter; allocated once.
  return static_cast<std::size_t>(std::ceil(o.buffer_s * o.imu_rate_hz * 1.1)) + 8;
}

}  // namespace

ImuFilter::ImuFilter(const PredictorOptions& options) : options_(options), history_(history_capacity(options)) {}

void ImuFilter::step(NavState& x, ErrorCovariance& P, const ImuSample& from, const ImuSample& to) const {
  propagate(x, P, from, to, options_.mount, options_.imu_noise);
  const double gap = to.t_s - from.t_s;
  if (!(gap > options_.dropout_gap_s)) return;
  // Unknown rate w and acceleration a held over the gap: dtheta = w gap, dv = a gap,
  // dp = a gap^2 / 2 (cross terms between them left out).
  const double sw = options_.dropout_gyro_sigma_radps * gap, sa = options_.dropout_accel_sigma_mps2 * gap;
  P.diagonal().segment<3>(err::theta).array() += sw * sw;
  P.diagonal().segment<3>(err::v).array() += sa * sa;
  P.diagonal().segment<3>(err::p).array() += 0.25 * sa * sa * gap * gap;
}

bool ImuFilter::state_at(double t_s, StateEntry& out, double& extrapolated_s) const {
  const std::optional<std::uint64_t> k = history_.find_at_or_before(t_s);
  const StateEntry* base = history_.base_at_or_before(t_s, k);
  if (!base) return false;
  // The reading at t_s: between the neighbouring samples, or the newest one held beyond them.
  const std::uint64_t next = k ? *k + 1 : history_.oldest_seq();
  out.x = base->x;
  out.P = base->P;
  if (next < history_.end_seq()) {
    out.sample = interpolate(base->sample, history_.at(next).sample, t_s);
    extrapolated_s = 0;
  } else {
    out.sample = base->sample;
    out.sample.t_s = t_s;
    extrapolated_s = t_s - base->sample.t_s;
    if (extrapolated_s > options_.coast_after_s) {
      // Coasting (no sample for longer than the bus's latency): over the gap the acceleration is
      // unknown with mean zero (the dropout inflation's model), so the reading held at the
      // extrapolation's end is the one of a camera that does not accelerate. Holding the last one
      // instead integrated a walking step's peak over the whole gap: 0.3 s of bus-off inside a
      // burst left the velocity 1.5 m/s off (docs/fusion.md, "Without vision"). Shorter
      // extrapolations (the newest sample's latency, the 5 ms look-ahead of the clock offset's
      // uncertainty) keep the held reading.
      const Eigen::Matrix3d imu_R_obj = (base->x.obj_R_cam * options_.mount.cam_R_imu).transpose();
      out.sample.accel_mps2 = base->x.accel_bias_mps2 - imu_R_obj * base->x.gravity_obj_mps2();
    }
  }
  step(out.x, out.P, base->sample, out.sample);
  return true;
}

bool ImuFilter::add(const ImuSample& s) {
  const StateEntry* base = history_.newest_state();
  StateEntry& e = history_.push(s, base != nullptr);  // never `base`: the history has >= 2 slots
  if (!base) return false;
  e.x = base->x;
  e.P = base->P;
  step(e.x, e.P, base->sample, s);
  return true;
}

void ImuFilter::repropagate_after(double t_s) {
  const std::optional<std::uint64_t> k = history_.find_at_or_before(t_s);
  const StateEntry* prev = history_.anchor();
  for (std::uint64_t seq = k ? *k + 1 : history_.oldest_seq(); seq < history_.end_seq(); ++seq) {
    StateEntry& e = history_.at(seq);
    e.x = prev->x;
    e.P = prev->P;
    step(e.x, e.P, prev->sample, e.sample);
    prev = &e;
    ++repropagated_samples_;
  }
}

bool ImuFilter::initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  NavState x = nav_state_from(cam_T_obj);
  // Gravity from the accelerometer averaged over the window before the exposure time (not after
  // it, so that the result does not depend on how late the pose arrives), assuming the camera does not
  // accelerate on average over the window (docs/fusion.md). Motion makes that wrong: the
  // gravity direction's initial uncertainty grows with the mismatch of |f| against g, with the
  // spread of the readings and with the rotation inside the window.
  const double window = options_.gravity_average_s;
  Eigen::Vector3d sum_f = Eigen::Vector3d::Zero(), sum_ff = Eigen::Vector3d::Zero();
  double sum_rate = 0;
  int n = 0;
  for (std::uint64_t seq = history_.oldest_seq(); seq < history_.end_seq(); ++seq) {
    const ImuSample& s = history_.at(seq).sample;
    if (s.t_s < t_s - window || s.t_s > t_s) continue;
    sum_f += s.accel_mps2;
    sum_ff += s.accel_mps2.cwiseAbs2();
    sum_rate += s.gyro_radps.norm();
    ++n;
  }
  if (n == 0) return false;
  const Eigen::Vector3d f_mean = sum_f / n;
  const double spread = std::sqrt(std::max(0.0, (sum_ff / n - f_mean.cwiseAbs2()).sum()));
  const double sigma_grav = std::min(
      0.5, options_.initial_gravity_rad + std::abs(f_mean.norm() - standard_gravity_mps2) / standard_gravity_mps2 +
               spread / standard_gravity_mps2 + sum_rate / n * 0.5 * window);
  x.obj_R_grav = gravity_frame_from(-(x.obj_R_cam * options_.mount.cam_R_imu * f_mean));

  ErrorCovariance P = ErrorCovariance::Zero();
  const Matrix6d J = geometry::filter_pose_error_jacobian(x.obj_R_cam);
  P.topLeftCorner<6, 6>() = J * start_covariance(cov) * J.transpose();
  const auto sq = [](double s) { return s * s; };
  P.diagonal().segment<3>(err::v).setConstant(sq(options_.initial_speed_mps));
  P.diagonal().segment<3>(err::bg).setConstant(sq(options_.initial_gyro_bias_radps));
  P.diagonal().segment<3>(err::ba).setConstant(sq(options_.initial_accel_bias_mps2));
  P.diagonal().segment<2>(err::grav).setConstant(sq(sigma_grav));
  if (carry_pending_) {
    x.obj_v_cam = carried_.obj_v_cam;
    x.gyro_bias_radps = carried_.gyro_bias_radps;
    x.accel_bias_mps2 = carried_.accel_bias_mps2;
    x.obj_R_grav = carried_.obj_R_grav;
    // The motion blocks (velocity .. gravity) with their correlations; none with the new pose.
    constexpr int first = err::v, n = err::dim - err::v;
    P.block<n, n>(first, first) = carried_P_.block<n, n>(first, first);
    carry_pending_ = false;
  }

  // The reading at the exposure time, for the first step after it.
  const std::optional<std::uint64_t> k = history_.find_at_or_before(t_s);
  const std::uint64_t next = k ? *k + 1 : history_.oldest_seq();
  StateEntry anchor;
  if (k && next < history_.end_seq()) anchor.sample = interpolate(history_.at(*k).sample, history_.at(next).sample, t_s);
  else anchor.sample = history_.at(k ? *k : next).sample;
  anchor.sample.t_s = t_s;
  anchor.x = x;
  anchor.P = P;
  history_.set_anchor(anchor);
  history_.set_first_state_seq(next);
  repropagate_after(t_s);
  return true;
}

Matrix6d ImuFilter::with_timing_uncertainty(double t_s, const StateEntry& at_t, const Matrix6d& cov) const {
  const double sigma_s = options_.imu_time_offset_sigma_s;
  if (!(sigma_s > 0)) return cov;
  // The pose's rate as a left perturbation (the vision covariance's convention), from the filter
  // a few milliseconds on: the IMU's own propagation, so rotation and translation both count.
  constexpr double kStepS = 0.005;
  StateEntry ahead;
  double extrapolated_s = 0;
  if (!state_at(t_s + kStepS, ahead, extrapolated_s)) return cov;
  const Vector6d rate = geometry::se3_log(ahead.x.cam_T_obj() * at_t.x.cam_T_obj().inverse()) / kStepS;
  if (!rate.allFinite()) return cov;
  return cov + (sigma_s * sigma_s) * rate * rate.transpose();
}

std::optional<PoseUpdateResult> ImuFilter::update(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov,
                                                  double gate_chi2) {
  StateEntry at_t;
  double extrapolated_s = 0;
  if (!state_at(t_s, at_t, extrapolated_s)) return std::nullopt;
  const PoseUpdateResult r = update_pose(at_t.x, at_t.P, cam_T_obj, with_timing_uncertainty(t_s, at_t, cov), gate_chi2);
  if (!r.applied) return r;
  history_.set_anchor(at_t);
  repropagate_after(t_s);
  return r;
}

std::optional<PosePrediction> ImuFilter::predict(double t_s) const {
  StateEntry e;
  PosePrediction out;
  if (!state_at(t_s, e, out.extrapolated_s)) return std::nullopt;
  const PoseJacobian H = pose_jacobian(e.x);
  out.t_s = t_s;
  out.cam_T_obj = e.x.cam_T_obj();
  out.covariance = H * e.P * H.transpose();
  return out;
}

StateEntry* ImuFilter::newest_sample_state() {
  if (history_.empty() || history_.end_seq() <= history_.first_state_seq()) return nullptr;
  const StateEntry* anchor = history_.anchor();
  StateEntry& e = history_.at(history_.end_seq() - 1);
  if (anchor && anchor->sample.t_s > e.sample.t_s) return nullptr;  // a pose applied ahead of it
  return &e;
}

double ImuFilter::update_t_s() const {
  const StateEntry* a = history_.anchor();
  return a ? a->sample.t_s : 0;
}

void ImuFilter::carry_motion(const NavState& motion, const ErrorCovariance& covariance) {
  carried_ = motion;
  carried_P_ = 0.5 * (covariance + covariance.transpose());
  carry_pending_ = true;
}

}  // namespace epichead::fusion
