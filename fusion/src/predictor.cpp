#include "epichead/fusion/predictor.h"

#include <algorithm>
#include <cmath>

#include "epichead/fusion/pose_update.h"
#include "epichead/geometry/pose_covariance.h"
#include "epichead/geometry/se3.h"

namespace epichead::fusion {
namespace {

bool finite(double v) { return std::isfinite(v); }

// Positive-definite and finite, as a Kalman measurement covariance must be.
bool usable_covariance(const Matrix6d& cov) {
  if (!cov.allFinite()) return false;
  if (!(cov - cov.transpose()).isZero(1e-9 * std::max(1.0, cov.cwiseAbs().maxCoeff()))) return false;
  return Eigen::LLT<Matrix6d>(cov).info() == Eigen::Success;
}

bool is_rotation(const Eigen::Matrix3d& R) {
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 &&
         R.determinant() > 0;
}

std::expected<void, std::string> check(const PredictorOptions& o) {
  const auto bad = [](const char* field, const char* what) {
    return std::unexpected(std::string("predictor options: ") + field + " " + what);
  };
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  const auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  const ImuNoise& n = o.imu_noise;
  if (!non_negative(n.gyro_noise_radps_rthz) || !non_negative(n.accel_noise_mps2_rthz) ||
      !non_negative(n.gyro_bias_walk_radps_rths) || !non_negative(n.accel_bias_walk_mps2_rths) ||
      !non_negative(n.gravity_walk_rad_rths))
    return bad("imu_noise", "must be finite and >= 0");
  if (!is_rotation(o.mount.cam_R_imu)) return bad("mount.cam_R_imu", "is not a rotation matrix");
  if (!finite(o.imu_time_offset_s)) return bad("imu_time_offset_s", "is not finite");
  if (!finite(o.imu_time_offset_sigma_s) || o.imu_time_offset_sigma_s < 0 || o.imu_time_offset_sigma_s > 1)
    return bad("imu_time_offset_sigma_s", "must be in [0, 1] s");
  if (!positive(o.imu_rate_hz) || o.imu_rate_hz > 1e5) return bad("imu_rate_hz", "must be in (0, 1e5]");
  if (!positive(o.buffer_s) || o.buffer_s > 10) return bad("buffer_s", "must be in (0, 10]");
  if (!(o.gyro_range_radps > 0) || !(o.accel_range_mps2 > 0)) return bad("gyro/accel range", "must be > 0");
  if (!positive(o.dropout_gap_s)) return bad("dropout_gap_s", "must be > 0");
  if (!non_negative(o.dropout_gyro_sigma_radps) || !non_negative(o.dropout_accel_sigma_mps2))
    return bad("dropout_*_sigma", "must be finite and >= 0");
  if (!positive(o.coast_after_s)) return bad("coast_after_s", "must be > 0");
  if (!positive(o.gate_chi2)) return bad("gate_chi2", "must be > 0");
  if (o.reinit_after_gated < 1) return bad("reinit_after_gated", "must be >= 1");
  if (!positive(o.gravity_average_s)) return bad("gravity_average_s", "must be > 0");
  if (!positive(o.initial_gravity_rad) || !positive(o.initial_speed_mps) || !positive(o.initial_gyro_bias_radps) ||
      !positive(o.initial_accel_bias_mps2))
    return bad("initial_*", "must be > 0");
  const ConstantVelocityNoise& c = o.cv_noise;
  if (!positive(c.accel_mps2_rths) || !positive(c.angular_accel_radps2_rths) || !positive(c.initial_speed_mps) ||
      !positive(c.initial_rate_radps))
    return bad("cv_noise", "must be finite and > 0");
  return {};
}

}  // namespace

const char* to_string(ImuVerdict v) {
  switch (v) {
    case ImuVerdict::Accepted: return "accepted";
    case ImuVerdict::Buffered: return "buffered";
    case ImuVerdict::NonFinite: return "non-finite";
    case ImuVerdict::Saturated: return "saturated";
    case ImuVerdict::OutOfOrder: return "out-of-order";
    case ImuVerdict::Duplicate: return "duplicate";
    case ImuVerdict::TimeJump: return "time-jump";
    case ImuVerdict::Ignored: return "ignored";
  }
  return "?";
}

const char* to_string(VisionVerdict v) {
  switch (v) {
    case VisionVerdict::Applied: return "applied";
    case VisionVerdict::Initialised: return "initialised";
    case VisionVerdict::Gated: return "gated";
    case VisionVerdict::TooOld: return "too-old";
    case VisionVerdict::OutOfOrder: return "out-of-order";
    case VisionVerdict::BadInput: return "bad-input";
    case VisionVerdict::NoImu: return "no-imu";
  }
  return "?";
}

std::expected<Predictor, std::string> Predictor::create(const PredictorOptions& options) {
  if (auto ok = check(options); !ok) return std::unexpected(ok.error());
  return Predictor(options);
}

Predictor::Predictor(const PredictorOptions& options) : options_(options), cv_(options.cv_noise) {
  // 10 % and a few samples of headroom for clock jitter; allocated once.
  const auto capacity = static_cast<std::size_t>(std::ceil(options.buffer_s * options.imu_rate_hz * 1.1)) + 8;
  ring_.resize(options.mode == PredictorMode::ImuAided ? capacity : 2);
}

std::optional<std::uint64_t> Predictor::find_at_or_before(double t_s) const {
  // Times in the ring increase strictly: binary search for the last entry with time <= t_s.
  std::uint64_t lo = oldest_seq(), hi = end_seq_;
  if (lo == hi || at(lo).sample.t_s > t_s) return std::nullopt;
  while (hi - lo > 1) {
    const std::uint64_t mid = lo + (hi - lo) / 2;
    if (at(mid).sample.t_s <= t_s) lo = mid; else hi = mid;
  }
  return lo;
}

const Predictor::Entry* Predictor::newest_state() const {
  const Entry* entry = nullptr;
  if (count_ > 0 && end_seq_ - 1 >= valid_from_seq_) entry = &at(end_seq_ - 1);
  if (anchor_.valid && (!entry || anchor_.e.sample.t_s >= entry->sample.t_s)) entry = &anchor_.e;
  return initialised_ ? entry : nullptr;
}

void Predictor::step(NavState& x, ErrorCovariance& P, const ImuSample& from, const ImuSample& to) const {
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

bool Predictor::state_at(double t_s, Entry& out, double& extrapolated_s) const {
  const std::optional<std::uint64_t> k = find_at_or_before(t_s);
  const Entry* base = nullptr;
  if (k && *k >= valid_from_seq_) base = &at(*k);
  if (anchor_.valid && anchor_.e.sample.t_s <= t_s && anchor_.e.sample.t_s >= evicted_t_s_ &&
      (!base || anchor_.e.sample.t_s >= base->sample.t_s))
    base = &anchor_.e;
  if (!base) return false;
  // The reading at t_s: between the neighbouring samples, or the newest one held beyond them.
  const std::uint64_t next = k ? *k + 1 : oldest_seq();
  out.x = base->x;
  out.P = base->P;
  if (next < end_seq_) {
    out.sample = interpolate(base->sample, at(next).sample, t_s);
    extrapolated_s = 0;
  } else {
    out.sample = base->sample;
    out.sample.t_s = t_s;
    extrapolated_s = t_s - base->sample.t_s;
  }
  step(out.x, out.P, base->sample, out.sample);
  return true;
}

ImuVerdict Predictor::add_imu(const ImuSample& in) {
  PredictorCounters& c = status_.counters;
  if (options_.mode == PredictorMode::ConstantVelocity) {
    ++c.imu_ignored;
    return ImuVerdict::Ignored;
  }
  if (!finite(in.t_s) || !in.gyro_radps.allFinite() || !in.accel_mps2.allFinite()) {
    ++c.imu_non_finite;
    return ImuVerdict::NonFinite;
  }
  // The simulator and real IMUs clip at the range, so a reading at the range is not trusted.
  if ((in.gyro_radps.cwiseAbs().array() >= options_.gyro_range_radps).any() ||
      (in.accel_mps2.cwiseAbs().array() >= options_.accel_range_mps2).any()) {
    ++c.imu_saturated;
    return ImuVerdict::Saturated;
  }
  ImuSample s = in;
  s.t_s = in.t_s - options_.imu_time_offset_s;
  if (count_ > 0) {
    const double newest = at(end_seq_ - 1).sample.t_s;
    if (std::abs(s.t_s - newest) > options_.buffer_s) {
      // One wild stamp must not lock the stream out (every later sample would be out of order),
      // so it is rejected; a stream that stays there is a restarted or stepped device clock:
      // three such samples in a row drop the ring and the state and start afresh.
      const bool follows = jumps_in_a_row_ > 0 && s.t_s > last_jump_t_s_ && s.t_s - last_jump_t_s_ <= options_.dropout_gap_s;
      jumps_in_a_row_ = follows ? jumps_in_a_row_ + 1 : 1;
      last_jump_t_s_ = s.t_s;
      if (jumps_in_a_row_ < 3) { ++c.imu_time_jump; return ImuVerdict::TimeJump; }
      ++c.imu_restarts;
      reset();
      count_ = 0;
      valid_from_seq_ = end_seq_;
      evicted_t_s_ = -1e300;
    } else {
      if (s.t_s == newest) { ++c.imu_duplicate; return ImuVerdict::Duplicate; }
      if (s.t_s < newest) { ++c.imu_out_of_order; return ImuVerdict::OutOfOrder; }
    }
  }
  jumps_in_a_row_ = 0;
  if (count_ > 0) {
    const double newest = at(end_seq_ - 1).sample.t_s;
    if (s.t_s - newest > options_.dropout_gap_s) {
      ++c.dropouts;
      c.dropout_total_s += s.t_s - newest;
    }
  }
  // A pose ahead of the newest sample (applied during a dropout) put the state there already.
  if (initialised_ && anchor_.valid && s.t_s < anchor_.e.sample.t_s) {
    ++c.imu_out_of_order;
    return ImuVerdict::OutOfOrder;
  }
  const Entry* base = newest_state();
  if (count_ == ring_.size()) evicted_t_s_ = at(oldest_seq()).sample.t_s;
  Entry& e = at(end_seq_);  // the ring has >= 2 slots, so this is never `base`
  e.sample = s;
  if (base) {
    e.x = base->x;
    e.P = base->P;
    step(e.x, e.P, base->sample, s);
  } else if (valid_from_seq_ <= end_seq_) {
    valid_from_seq_ = end_seq_ + 1;  // not initialised: this entry holds only the sample
  }
  ++end_seq_;
  count_ = std::min<std::uint64_t>(count_ + 1, ring_.size());
  status_.newest_imu_t_s = s.t_s;
  if (!base) { ++c.imu_buffered; return ImuVerdict::Buffered; }
  ++c.imu_accepted;
  return ImuVerdict::Accepted;
}

void Predictor::repropagate_after(double t_s) {
  const std::optional<std::uint64_t> k = find_at_or_before(t_s);
  const Entry* prev = &anchor_.e;
  for (std::uint64_t seq = k ? *k + 1 : oldest_seq(); seq < end_seq_; ++seq) {
    Entry& e = at(seq);
    e.x = prev->x;
    e.P = prev->P;
    step(e.x, e.P, prev->sample, e.sample);
    prev = &e;
    ++status_.counters.repropagated_samples;
  }
}

VisionResult Predictor::initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  PredictorCounters& c = status_.counters;
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
  for (std::uint64_t seq = oldest_seq(); seq < end_seq_; ++seq) {
    const ImuSample& s = at(seq).sample;
    if (s.t_s < t_s - window || s.t_s > t_s) continue;
    sum_f += s.accel_mps2;
    sum_ff += s.accel_mps2.cwiseAbs2();
    sum_rate += s.gyro_radps.norm();
    ++n;
  }
  if (n == 0) {
    ++c.vision_no_imu;
    return {VisionVerdict::NoImu, 0};
  }
  const Eigen::Vector3d f_mean = sum_f / n;
  const double spread = std::sqrt(std::max(0.0, (sum_ff / n - f_mean.cwiseAbs2()).sum()));
  const double sigma_grav = std::min(
      0.5, options_.initial_gravity_rad + std::abs(f_mean.norm() - standard_gravity_mps2) / standard_gravity_mps2 +
               spread / standard_gravity_mps2 + sum_rate / n * 0.5 * window);
  x.obj_R_grav = gravity_frame_from(-(x.obj_R_cam * options_.mount.cam_R_imu * f_mean));

  ErrorCovariance P = ErrorCovariance::Zero();
  const Matrix6d J = geometry::filter_pose_error_jacobian(x.obj_R_cam);
  P.topLeftCorner<6, 6>() = J * cov * J.transpose();
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
  const std::optional<std::uint64_t> k = find_at_or_before(t_s);
  const std::uint64_t next = k ? *k + 1 : oldest_seq();
  if (k && next < end_seq_) anchor_.e.sample = interpolate(at(*k).sample, at(next).sample, t_s);
  else anchor_.e.sample = at(k ? *k : next).sample;
  anchor_.e.sample.t_s = t_s;
  anchor_.e.x = x;
  anchor_.e.P = P;
  anchor_.valid = true;
  valid_from_seq_ = next;
  repropagate_after(t_s);

  if (c.vision_initialised > 0) ++c.reinitialisations;
  ++c.vision_initialised;
  initialised_ = true;
  reinit_pending_ = false;
  status_.gated_in_a_row = 0;
  status_.last_update_t_s = t_s;
  return {VisionVerdict::Initialised, 0};
}

VisionResult Predictor::add_vision_cv(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  PredictorCounters& c = status_.counters;
  if (!initialised_ || reinit_pending_) {
    cv_.initialise(t_s, cam_T_obj, cov);
    if (c.vision_initialised > 0) ++c.reinitialisations;
    ++c.vision_initialised;
    initialised_ = true;
    reinit_pending_ = false;
    status_.gated_in_a_row = 0;
    status_.last_update_t_s = t_s;
    return {VisionVerdict::Initialised, 0};
  }
  if (t_s <= cv_.time()) {
    ++c.vision_out_of_order;
    return {VisionVerdict::OutOfOrder, 0};
  }
  const PoseUpdateResult r = cv_.update(t_s, cam_T_obj, cov, options_.gate_chi2);
  if (!r.applied) {
    ++c.vision_gated;
    if (++status_.gated_in_a_row >= options_.reinit_after_gated) reinit_pending_ = true;
    return {VisionVerdict::Gated, r.mahalanobis2};
  }
  ++c.vision_applied;
  status_.gated_in_a_row = 0;
  status_.last_nis = r.mahalanobis2;
  status_.last_update_t_s = t_s;
  return {VisionVerdict::Applied, r.mahalanobis2};
}

Matrix6d Predictor::with_timing_uncertainty(double t_s, const Entry& at_t, const Matrix6d& cov) const {
  const double sigma_s = options_.imu_time_offset_sigma_s;
  if (!(sigma_s > 0)) return cov;
  // The pose's rate as a left perturbation (the vision covariance's convention), from the filter
  // a few milliseconds on: the IMU's own propagation, so rotation and translation both count.
  constexpr double kStepS = 0.005;
  Entry ahead;
  double extrapolated_s = 0;
  if (!state_at(t_s + kStepS, ahead, extrapolated_s)) return cov;
  const Vector6d rate = geometry::se3_log(ahead.x.cam_T_obj() * at_t.x.cam_T_obj().inverse()) / kStepS;
  if (!rate.allFinite()) return cov;
  return cov + (sigma_s * sigma_s) * rate * rate.transpose();
}

VisionResult Predictor::add_vision(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov_in) {
  PredictorCounters& c = status_.counters;
  const bool far_ahead = options_.mode == PredictorMode::ImuAided && count_ > 0 &&
                         t_s > at(end_seq_ - 1).sample.t_s + options_.buffer_s;
  if (!finite(t_s) || far_ahead || !cam_T_obj.matrix().allFinite() || !is_rotation(cam_T_obj.linear()) ||
      !usable_covariance(cov_in)) {
    ++c.vision_bad_input;
    return {VisionVerdict::BadInput, 0};
  }
  const Matrix6d cov = 0.5 * (cov_in + cov_in.transpose());
  if (options_.mode == PredictorMode::ConstantVelocity) return add_vision_cv(t_s, cam_T_obj, cov);
  if (!initialised_ || reinit_pending_) return initialise(t_s, cam_T_obj, cov);
  // Poses come in exposure order; one older than the last applied would undo it on re-propagation.
  if (anchor_.valid && t_s <= anchor_.e.sample.t_s) {
    ++c.vision_out_of_order;
    return {VisionVerdict::OutOfOrder, 0};
  }
  Entry at_t;
  double extrapolated_s = 0;
  if (!state_at(t_s, at_t, extrapolated_s)) {
    ++c.vision_too_old;
    return {VisionVerdict::TooOld, 0};
  }
  const PoseUpdateResult r = update_pose(at_t.x, at_t.P, cam_T_obj, with_timing_uncertainty(t_s, at_t, cov), options_.gate_chi2);
  if (!r.applied) {
    ++c.vision_gated;
    if (++status_.gated_in_a_row >= options_.reinit_after_gated) reinit_pending_ = true;
    return {VisionVerdict::Gated, r.mahalanobis2};
  }
  anchor_.e = at_t;
  anchor_.valid = true;
  repropagate_after(t_s);
  ++c.vision_applied;
  status_.gated_in_a_row = 0;
  status_.last_nis = r.mahalanobis2;
  status_.last_update_t_s = t_s;
  return {VisionVerdict::Applied, r.mahalanobis2};
}

std::optional<PosePrediction> Predictor::predict(double t_s) const {
  if (!initialised_ || !finite(t_s)) return std::nullopt;
  if (options_.mode == PredictorMode::ConstantVelocity) return cv_.predict(t_s);
  Entry e;
  PosePrediction out;
  if (!state_at(t_s, e, out.extrapolated_s)) return std::nullopt;
  const PoseJacobian H = pose_jacobian(e.x);
  out.t_s = t_s;
  out.cam_T_obj = e.x.cam_T_obj();
  out.covariance = H * e.P * H.transpose();
  return out;
}

PredictorStatus Predictor::status(double now_t_s) const {
  PredictorStatus s = status_;
  s.initialised = initialised_;
  s.coasting = initialised_ && options_.mode == PredictorMode::ImuAided &&
               (count_ == 0 || !(now_t_s - status_.newest_imu_t_s <= options_.coast_after_s));
  return s;
}

void Predictor::carry_motion(const NavState& motion, const ErrorCovariance& covariance) {
  carried_ = motion;
  carried_P_ = 0.5 * (covariance + covariance.transpose());
  carry_pending_ = true;
}

void Predictor::reset() {
  initialised_ = false;
  reinit_pending_ = false;
  anchor_.valid = false;
  valid_from_seq_ = end_seq_;
  status_.gated_in_a_row = 0;
}

std::optional<NavState> Predictor::state() const {
  const Entry* e = newest_state();
  if (!e) return std::nullopt;
  return e->x;
}

const ErrorCovariance& Predictor::covariance() const {
  static const ErrorCovariance none = ErrorCovariance::Zero();
  const Entry* e = newest_state();
  return e ? e->P : none;
}

double Predictor::state_t_s() const {
  const Entry* e = newest_state();
  return e ? e->sample.t_s : 0;
}

}  // namespace epichead::fusion
