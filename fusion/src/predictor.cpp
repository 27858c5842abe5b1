#include "epichead/fusion/predictor.h"

#include <algorithm>
#include <cmath>

#include "epichead/fusion/unaided_update.h"
#include "epichead/geometry/pose_covariance.h"

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
  const GravityCheckOptions& g = o.gravity_check;
  if (g.learn_after_applied < 1 || !positive(g.learn_sigma_rad) || !positive(g.learn_time_s) || !positive(g.window_s) ||
      !non_negative(g.min_window_s) || g.min_window_s > g.window_s || !positive(g.max_tilt_error_rad) ||
      !positive(g.forget_after_s))
    return bad("gravity_check", "needs learn_after_applied >= 1, 0 <= min_window_s <= window_s and the rest finite and > 0");
  if (g.told_down_obj && !(g.told_down_obj->allFinite() && g.told_down_obj->norm() > 1e-9))
    return bad("gravity_check.told_down_obj", "must be a finite, non-zero direction");
  const UnaidedOptions& u = o.unaided;
  if (!positive(u.after_s) || !positive(u.period_s) || !positive(u.down_sigma_rad) || !positive(u.max_force_error) ||
      !positive(u.position_sigma_m))
    return bad("unaided", "must be finite and > 0");
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
    case VisionVerdict::AgainstGravity: return "against-gravity";
    case VisionVerdict::Unchecked: return "unchecked";
  }
  return "?";
}

std::expected<Predictor, std::string> Predictor::create(const PredictorOptions& options) {
  if (auto ok = check(options); !ok) return std::unexpected(ok.error());
  return Predictor(options);
}

Predictor::Predictor(const PredictorOptions& options)
    : options_(options), imu_(options), cv_(options.cv_noise), gravity_(options.gravity_check) {}

PoseFilter& Predictor::filter() {
  if (options_.mode == PredictorMode::ConstantVelocity) return cv_;
  return imu_;
}

const PoseFilter& Predictor::filter() const {
  if (options_.mode == PredictorMode::ConstantVelocity) return cv_;
  return imu_;
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
  const StateHistory& history = imu_.history();
  if (!history.empty()) {
    const double newest = history.newest_sample().t_s;
    if (std::abs(s.t_s - newest) > options_.buffer_s) {
      // One wild stamp must not lock the stream out (every later sample would be out of order),
      // so it is rejected; a stream that stays there is a restarted or stepped device clock:
      // three such samples in a row drop the history and the state and start afresh.
      const bool follows = jumps_in_a_row_ > 0 && s.t_s > last_jump_t_s_ && s.t_s - last_jump_t_s_ <= options_.dropout_gap_s;
      jumps_in_a_row_ = follows ? jumps_in_a_row_ + 1 : 1;
      last_jump_t_s_ = s.t_s;
      if (jumps_in_a_row_ < 3) { ++c.imu_time_jump; return ImuVerdict::TimeJump; }
      ++c.imu_restarts;
      reset();
      imu_.clear();
    } else {
      if (s.t_s == newest) { ++c.imu_duplicate; return ImuVerdict::Duplicate; }
      if (s.t_s < newest) { ++c.imu_out_of_order; return ImuVerdict::OutOfOrder; }
    }
  }
  jumps_in_a_row_ = 0;
  if (!history.empty()) {
    const double newest = history.newest_sample().t_s;
    if (s.t_s - newest > options_.dropout_gap_s) {
      ++c.dropouts;
      c.dropout_total_s += s.t_s - newest;
    }
  }
  // A pose ahead of the newest sample (applied during a dropout) put the state there already.
  if (initialised_ && s.t_s < imu_.update_t_s()) {
    ++c.imu_out_of_order;
    return ImuVerdict::OutOfOrder;
  }
  const bool propagated = imu_.add(s);
  status_.newest_imu_t_s = s.t_s;
  if (!propagated) { ++c.imu_buffered; return ImuVerdict::Buffered; }
  ++c.imu_accepted;
  update_unaided(s.t_s);
  return ImuVerdict::Accepted;
}

void Predictor::update_unaided(double t_s) {
  const UnaidedOptions& u = options_.unaided;
  if (!u.enabled || !initialised_ || t_s - status_.last_update_t_s < u.after_s) return;
  StateEntry* e = imu_.newest_sample_state();
  if (!e) return;
  PredictorCounters& c = status_.counters;
  if (!unaided_floored_) {
    // Going unaided: the pose is known no better than the last vision pose said (unaided_update.h).
    unaided_floored_ = true;
    const Matrix6d J = geometry::filter_pose_error_jacobian(e->x.obj_R_cam);
    c.unaided_pose_floors += floor_pose_covariance(e->P, J * last_vision_cov_ * J.transpose());
  }
  if (gravity_.learnt() && t_s >= next_down_t_s_) {
    // A window too short (after a gap) or a camera accelerating: tried again a tenth of the period
    // later, not at every sample (each try turns up to window_s of samples: ~20 us).
    next_down_t_s_ = t_s + 0.1 * u.period_s;
    // The down without the filter's mean acceleration: unaided, its velocity is its own propagation,
    // and the acceleration from it would only give back the filter's own tilt.
    const GravityCheckOptions& g = options_.gravity_check;
    const std::optional<MeanForce> force = mean_specific_force(imu_.history(), t_s, g.window_s, g.min_window_s, options_.dropout_gap_s,
                                                               gravity_.gyro_bias_radps(), gravity_.accel_bias_mps2());
    if (force && std::abs(force->mean_imu_mps2.norm() - standard_gravity_mps2) <= u.max_force_error * standard_gravity_mps2)
      if (const std::optional<Eigen::Vector3d> down_imu = down_from(*force)) {
        const Eigen::Vector3d down_cam = options_.mount.cam_R_imu * *down_imu;
        // A body of revolution: of the learnt down only its angle to the axis is known.
        const Eigen::Vector3d down_obj = gravity_.down_obj_toward(e->x.obj_R_cam * down_cam);
        const DownUpdateResult r = update_down(e->x, e->P, down_obj, down_cam, u.down_sigma_rad, g.max_tilt_error_rad);
        c.unaided_down_updates += r.applied;
        c.unaided_tilt_contradictions += r.inflated;
        next_down_t_s_ = t_s + u.period_s;
      }
  }
  if (have_hold_ && t_s >= next_hold_t_s_) {
    next_hold_t_s_ = t_s + u.period_s;
    if (hold_position(e->x, e->P, hold_obj_p_cam_, u.position_sigma_m)) ++c.unaided_position_holds;
  }
}

VisionResult Predictor::initialise_from(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  PoseFilter& f = filter();
  PredictorCounters& c = status_.counters;
  // Never restart from a wrong lock: the down learnt before decides (the filter's own state,
  // about to be replaced, may be the one that is wrong).
  if (check_tilt(t_s, cam_T_obj)) return {VisionVerdict::AgainstGravity, 0};
  // After a run of gated poses, one that cannot be checked (the accelerometer's window is cut by
  // a gap) may be the wrong lock the gap caused: the filter waits for one that can be.
  if (initialised_ && options_.mode == PredictorMode::ImuAided && gravity_.learnt() && !measured_down_cam(t_s)) {
    ++c.vision_unchecked;
    return {VisionVerdict::Unchecked, 0};
  }
  if (!f.initialise(t_s, cam_T_obj, cov)) {
    ++c.vision_no_imu;
    return {VisionVerdict::NoImu, 0};
  }
  if (c.vision_initialised > 0) ++c.reinitialisations;
  ++c.vision_initialised;
  initialised_ = true;
  reinit_pending_ = false;
  status_.gated_in_a_row = 0;
  applied_in_a_row_ = 0;
  status_.last_update_t_s = t_s;
  note_vision_cov(cov);
  note_hold(t_s, cam_T_obj);
  return {VisionVerdict::Initialised, 0};
}

VisionResult Predictor::add_vision(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov_in) {
  PredictorCounters& c = status_.counters;
  const StateHistory& history = imu_.history();
  const bool far_ahead = options_.mode == PredictorMode::ImuAided && !history.empty() &&
                         t_s > history.newest_sample().t_s + options_.buffer_s;
  if (!finite(t_s) || far_ahead || !cam_T_obj.matrix().allFinite() || !is_rotation(cam_T_obj.linear()) ||
      !usable_covariance(cov_in)) {
    ++c.vision_bad_input;
    return {VisionVerdict::BadInput, 0};
  }
  const Matrix6d cov = 0.5 * (cov_in + cov_in.transpose());
  PoseFilter& f = filter();
  if (!initialised_ || reinit_pending_) return initialise_from(t_s, cam_T_obj, cov);
  // Poses come in exposure order; one older than the last applied would undo it on re-propagation.
  if (t_s <= f.update_t_s()) {
    ++c.vision_out_of_order;
    return {VisionVerdict::OutOfOrder, 0};
  }
  const std::optional<PoseUpdateResult> r = f.update(t_s, cam_T_obj, cov, options_.gate_chi2);
  if (!r) {
    ++c.vision_too_old;
    return {VisionVerdict::TooOld, 0};
  }
  if (!r->applied) {
    ++c.vision_gated;
    applied_in_a_row_ = 0;
    if (resumes_after_gap(t_s, cam_T_obj)) {
      // Back after a stretch without an applied pose (a camera stall, lost and gated frames), the
      // state drifted further than its covariance says (a step's burst integrated from a velocity
      // the frames had not pinned down: docs/fusion.md, "Without vision"). Re-initialised from
      // this pose now, as PX4's EKF2 resets to an aiding source whose fusion timed out, rather
      // than after reinit_after_gated frames tracked from the drifted prediction, which lead the
      // tracker off too. The sensor's biases and the gravity direction are kept; the velocity
      // starts again from zero.
      carry_sensor_state();
      const VisionResult re = initialise_from(t_s, cam_T_obj, cov);
      if (re.verdict == VisionVerdict::Initialised) {
        ++c.resumption_resets;
        return re;
      }
      imu_.drop_carried_motion();
    }
    if (++status_.gated_in_a_row >= options_.reinit_after_gated) reinit_pending_ = true;
    return {VisionVerdict::Gated, r->mahalanobis2, r->dims};
  }
  ++c.vision_applied;
  status_.gated_in_a_row = 0;
  status_.last_nis = r->mahalanobis2;
  status_.last_update_t_s = t_s;
  ++applied_in_a_row_;
  note_vision_cov(cov);
  note_hold(t_s, cam_T_obj);
  if (options_.mode == PredictorMode::ImuAided)
    if (const StateEntry* e = imu_.newest_state()) {
      const double sigma = std::sqrt(e->P.block<2, 2>(err::grav, err::grav).diagonal().maxCoeff());
      gravity_.learn(t_s, e->x.gravity_obj_mps2(), sigma, e->x.gyro_bias_radps, e->x.accel_bias_mps2, applied_in_a_row_);
    }
  return {VisionVerdict::Applied, r->mahalanobis2, r->dims};
}

bool Predictor::resumes_after_gap(double t_s, const Eigen::Isometry3d& cam_T_obj) const {
  if (options_.mode != PredictorMode::ImuAided || !options_.unaided.enabled || !have_hold_) return false;
  // As PX4's EKF2 times out an aiding source: from the last measurement fused, not offered.
  if (!(t_s - status_.last_update_t_s > options_.unaided.after_s)) return false;
  // Only where the unaided filter's position hold allows the camera to be.
  const Eigen::Vector3d obj_p_cam = cam_T_obj.inverse().translation();
  return (obj_p_cam - hold_obj_p_cam_).norm() <= options_.unaided.position_sigma_m;
}

void Predictor::carry_sensor_state() {
  const StateEntry* e = imu_.newest_state();
  if (!e) return;
  NavState motion = e->x;
  motion.obj_v_cam.setZero();
  ErrorCovariance P = e->P;
  P.middleRows<3>(err::v).setZero();
  P.middleCols<3>(err::v).setZero();
  P.diagonal().segment<3>(err::v).setConstant(options_.initial_speed_mps * options_.initial_speed_mps);
  imu_.carry_motion(motion, P);
}

void Predictor::note_vision_cov(const Matrix6d& cov) {
  last_vision_cov_ = cov;
  unaided_floored_ = false;
}

void Predictor::note_hold(double t_s, const Eigen::Isometry3d& cam_T_obj) {
  if (options_.mode != PredictorMode::ImuAided) return;
  const StateEntry* anchor = imu_.history().anchor();
  if (!anchor) return;
  // A pose the accelerometer could not check (right after a gap) may be a wrong lock; one it
  // contradicted the caller did not give.
  if (gravity_.learnt()) {
    const std::optional<double> e = tilt_error_rad(t_s, cam_T_obj);
    if (!e || *e > options_.gravity_check.max_tilt_error_rad) return;
  }
  hold_obj_p_cam_ = anchor->x.obj_p_cam;
  have_hold_ = true;
}

std::optional<Eigen::Vector3d> Predictor::measured_down_cam(double t_s) const {
  if (options_.mode != PredictorMode::ImuAided || !finite(t_s)) return std::nullopt;
  // The biases learnt with the down, else the newest state's, else none (a fraction of a degree
  // over the window either way).
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero();
  if (gravity_.biases_learnt()) {
    bg = gravity_.gyro_bias_radps();
    ba = gravity_.accel_bias_mps2();
  } else if (const StateEntry* e = imu_.newest_state()) {
    bg = e->x.gyro_bias_radps;
    ba = e->x.accel_bias_mps2;
  }
  const GravityCheckOptions& o = options_.gravity_check;
  const StateHistory& h = imu_.history();
  const std::optional<MeanForce> force = mean_specific_force(h, t_s, o.window_s, o.min_window_s, options_.dropout_gap_s, bg, ba);
  if (!force) return std::nullopt;
  // A walking or hand-held camera accelerates on average over the window by up to a few m/s^2
  // (up to 13 deg of tilt on the can scene); the filter's velocity at both ends of the window
  // says by how much, when both carry a state.
  Eigen::Vector3d accel_imu = Eigen::Vector3d::Zero();
  if (force->oldest_seq >= h.first_state_seq()) {
    const StateEntry& a = h.at(force->oldest_seq);
    const StateEntry& b = h.at(force->newest_seq);
    const double dt = b.sample.t_s - a.sample.t_s;
    if (dt > 0) accel_imu = options_.mount.cam_R_imu.transpose() * b.x.obj_R_cam.transpose() * (b.x.obj_v_cam - a.x.obj_v_cam) / dt;
  }
  const std::optional<Eigen::Vector3d> down_imu = down_from(*force, accel_imu);
  if (!down_imu) return std::nullopt;
  return options_.mount.cam_R_imu * *down_imu;
}

std::optional<Eigen::Vector3d> Predictor::learnt_down_obj() const {
  if (!gravity_.learnt()) return std::nullopt;
  return gravity_.down_obj();
}

std::optional<double> Predictor::tilt_error_rad(double t_s, const Eigen::Isometry3d& cam_T_obj) const {
  if (!gravity_.learnt() || !cam_T_obj.matrix().allFinite()) return std::nullopt;
  return gravity_.tilt_error_rad(cam_T_obj.linear(), measured_down_cam(t_s));
}

bool Predictor::check_tilt(double t_s, const Eigen::Isometry3d& cam_T_obj) { return check_tilt(t_s, tilt_error_rad(t_s, cam_T_obj)); }

bool Predictor::replace_wrong_lock(double t_s, const Eigen::Isometry3d& cam_T_obj, double lock_since_s) {
  if (!gravity_.learnt() || gravity_.told() || gravity_.learnt_since_s() < lock_since_s) return false;
  const auto e = tilt_error_rad(t_s, cam_T_obj);
  if (!e || !(*e > options_.gravity_check.max_tilt_error_rad)) return false;
  gravity_.forget_learnt();
  ++status_.counters.gravity_forgotten;
  return true;
}

bool Predictor::check_tilt(double t_s, std::optional<double> e) {
  if (!e) return false;
  const bool against = *e > options_.gravity_check.max_tilt_error_rad;
  const int forgotten = gravity_.forgotten();
  gravity_.note_verdict(t_s, against);
  status_.counters.gravity_forgotten += static_cast<std::uint64_t>(gravity_.forgotten() - forgotten);
  if (against) ++status_.counters.vision_against_gravity;
  return against;
}

std::optional<PosePrediction> Predictor::predict(double t_s) const {
  if (!initialised_ || !finite(t_s)) return std::nullopt;
  return filter().predict(t_s);
}

PredictorStatus Predictor::status(double now_t_s) const {
  PredictorStatus s = status_;
  s.initialised = initialised_;
  s.gravity_learnt = gravity_.learnt();
  s.gravity_told = gravity_.told();
  s.coasting = initialised_ && options_.mode == PredictorMode::ImuAided &&
               (imu_.history().empty() || !(now_t_s - status_.newest_imu_t_s <= options_.coast_after_s));
  s.counters.repropagated_samples = imu_.repropagated_samples();
  return s;
}

void Predictor::carry_motion(const NavState& motion, const ErrorCovariance& covariance) {
  imu_.carry_motion(motion, covariance);
}

void Predictor::reset() {
  initialised_ = false;
  reinit_pending_ = false;
  filter().reset();
  status_.gated_in_a_row = 0;
}

VisionResult Predictor::restart_keeping_motion(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) {
  const std::optional<PosePrediction> before = predict(t_s);
  const StateEntry* e = imu_.newest_state();
  if (before && e && cam_T_obj.matrix().allFinite()) {
    // The newest state's motion: callers feed the IMU up to the exposure first, so it is at most a
    // sample later. The filter's object frame into the pose's: obj_new_R_obj_old = obj_new_R_cam *
    // cam_R_obj_old, the same at any instant when the filter's error is a fixed turn of the object.
    const Eigen::Matrix3d turn = cam_T_obj.linear().transpose() * before->cam_T_obj.linear();
    NavState motion = e->x;
    motion.obj_v_cam = turn * motion.obj_v_cam;
    motion.obj_R_grav = turn * motion.obj_R_grav;  // its error is local to the gravity frame: unchanged
    ErrorCovariance P = e->P;
    P.middleRows<3>(err::v) = turn * P.middleRows<3>(err::v);
    P.middleCols<3>(err::v) = P.middleCols<3>(err::v) * turn.transpose();
    imu_.carry_motion(motion, P);
  }
  reset();
  const VisionResult r = add_vision(t_s, cam_T_obj, cov);
  if (r.verdict != VisionVerdict::Initialised) imu_.drop_carried_motion();
  return r;
}

std::optional<NavState> Predictor::state() const {
  const StateEntry* e = imu_.newest_state();
  if (!e) return std::nullopt;
  return e->x;
}

const ErrorCovariance& Predictor::covariance() const {
  static const ErrorCovariance none = ErrorCovariance::Zero();
  const StateEntry* e = imu_.newest_state();
  return e ? e->P : none;
}

double Predictor::state_t_s() const {
  const StateEntry* e = imu_.newest_state();
  return e ? e->sample.t_s : 0;
}

}  // namespace epichead::fusion
