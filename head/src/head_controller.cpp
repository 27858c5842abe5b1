#include "epichead/head/head_controller.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace epichead::head {
namespace {

using firmware_iface::kHeadAngleRadPerLsb;
using firmware_iface::kHeadRateRadpsPerLsb;

bool finite(double v) { return std::isfinite(v); }
bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

std::expected<void, std::string> positive(double v, const char* field) {
  if (!finite(v) || !(v > 0)) return std::unexpected(std::string("head controller options: ") + field + " must be finite and positive");
  return {};
}
std::expected<void, std::string> non_negative(double v, const char* field) {
  if (!finite(v) || !(v >= 0)) return std::unexpected(std::string("head controller options: ") + field + " must be finite and not negative");
  return {};
}

// Wire field ranges (head_command.h): int16 angles, int12 rates.
constexpr std::int64_t kAngleRawMin = -32768, kAngleRawMax = 32767;
constexpr std::int64_t kRateRawMin = -2048, kRateRawMax = 2047;

// An angle on the wire's grid, never outside [min, max] (rounding may not step over a limit),
// then within the field's range. `clipped` counts a value the field cannot hold.
double wire_angle(double angle_rad, const JointLimits& l, std::uint64_t& clipped) {
  auto raw = static_cast<std::int64_t>(std::nearbyint(angle_rad / kHeadAngleRadPerLsb));
  if (static_cast<double>(raw) * kHeadAngleRadPerLsb > l.max_rad) --raw;
  if (static_cast<double>(raw) * kHeadAngleRadPerLsb < l.min_rad) ++raw;
  if (raw < kAngleRawMin || raw > kAngleRawMax) {
    raw = std::clamp(raw, kAngleRawMin, kAngleRawMax);
    ++clipped;
  }
  return static_cast<double>(raw) * kHeadAngleRadPerLsb;
}

double wire_rate(double rate_radps, std::uint64_t& clipped) {
  auto raw = static_cast<std::int64_t>(std::nearbyint(rate_radps / kHeadRateRadpsPerLsb));
  if (raw < kRateRawMin || raw > kRateRawMax) {
    raw = std::clamp(raw, kRateRawMin, kRateRawMax);
    ++clipped;
  }
  return static_cast<double>(raw) * kHeadRateRadpsPerLsb;
}

// Rotation from axis a to unit direction d as a rotation vector (axis * angle), robust for
// any angle below pi.
Eigen::Vector3d rotation_to(const Eigen::Vector3d& a, const Eigen::Vector3d& d) {
  const Eigen::Vector3d c = a.cross(d);
  const double s = c.norm();
  if (s < 1e-12) return Eigen::Vector3d::Zero();
  return c / s * std::atan2(s, a.dot(d));
}

Eigen::Vector2d clamp_norm(const Eigen::Vector2d& v, double max_norm) {
  const double n = v.norm();
  return n > max_norm ? Eigen::Vector2d(v * (max_norm / n)) : v;
}

double clamp_rate(double v, const JointLimits& l) { return std::clamp(v, -l.rate_max_radps, l.rate_max_radps); }

// Where a joint moving at rate v comes to rest decelerating at the limit, inside the limits.
double stopping_angle(const JointCommand& c, const JointLimits& l) {
  return std::clamp(c.angle_rad + c.rate_radps * std::abs(c.rate_radps) / (2 * l.accel_max_radps2), l.min_rad, l.max_rad);
}

}  // namespace

JointState joint_state_from(const firmware_iface::HeadState& state, double receive_t_s) {
  return {receive_t_s, {state.pan_rad, state.tilt_rad}, state.pan_rate_radps, state.tilt_rate_radps};
}

std::expected<HeadController, std::string> HeadController::create(const HeadControllerOptions& o) {
  if (auto ok = check(o.pan, "pan"); !ok) return std::unexpected(ok.error());
  if (auto ok = check(o.tilt, "tilt"); !ok) return std::unexpected(ok.error());
  const struct { double v; const char* name; } pos[] = {
      {o.rate_hz, "rate_hz"}, {o.fixate_max_rate_radps, "fixate_max_rate_radps"},
      {o.target_rate_filter_s, "target_rate_filter_s"}, {o.hold_max_rate_radps, "hold_max_rate_radps"},
      {o.park_rate_radps, "park_rate_radps"}, {o.rate_lead_filter_s, "rate_lead_filter_s"}, {o.park_tolerance_rad, "park_tolerance_rad"},
      {o.max_following_error_rad, "max_following_error_rad"}, {o.history_s, "history_s"},
      {o.joint_rates.correction_time_constant_s, "joint_rates.correction_time_constant_s"},
      {o.joint_rates.max_command_age_s, "joint_rates.max_command_age_s"},
      {o.watchdog.imu_timeout_s, "watchdog.imu_timeout_s"}, {o.watchdog.head_state_timeout_s, "watchdog.head_state_timeout_s"},
      {o.watchdog.target_timeout_s, "watchdog.target_timeout_s"}};
  for (const auto& p : pos)
    if (auto ok = positive(p.v, p.name); !ok) return std::unexpected(ok.error());
  const struct { double v; const char* name; } nonneg[] = {
      {o.stabilise_gain_per_s, "stabilise_gain_per_s"}, {o.fixate_gain_per_s, "fixate_gain_per_s"},
      {o.target_rate_max_radps, "target_rate_max_radps"}, {o.hold_gain_per_s, "hold_gain_per_s"},
      {o.switch_blend_s, "switch_blend_s"}, {o.rate_lead_s, "rate_lead_s"}, {o.body_rate_filter_s, "body_rate_filter_s"},
      {o.joint_rates.command_delay_s, "joint_rates.command_delay_s"}, {o.joint_rates.motor_lag_s, "joint_rates.motor_lag_s"}, {o.watchdog.imu_recover_s, "watchdog.imu_recover_s"},
      {o.watchdog.head_state_recover_s, "watchdog.head_state_recover_s"}, {o.watchdog.bus_recover_s, "watchdog.bus_recover_s"},
      {o.watchdog.lost_to_hold_s, "watchdog.lost_to_hold_s"}};
  for (const auto& p : nonneg)
    if (auto ok = non_negative(p.v, p.name); !ok) return std::unexpected(ok.error());
  if (o.rate_hz > 100e3) return std::unexpected("head controller options: rate_hz above 100 kHz");
  if (o.history_s > 10) return std::unexpected("head controller options: history_s above 10 s");
  if (!finite(o.park.pan_rad) || o.park.pan_rad < o.pan.min_rad || o.park.pan_rad > o.pan.max_rad)
    return std::unexpected("head controller options: park.pan_rad outside the pan limits");
  if (!finite(o.park.tilt_rad) || o.park.tilt_rad < o.tilt.min_rad || o.park.tilt_rad > o.tilt.max_rad)
    return std::unexpected("head controller options: park.tilt_rad outside the tilt limits");
  for (const auto& [v, name] : {std::pair{o.backlash.pan_rad, "backlash.pan_rad"},
                                 std::pair{o.backlash.tilt_rad, "backlash.tilt_rad"}}) {
    if (auto ok = non_negative(v, name); !ok) return std::unexpected(ok.error());
    if (v > 0.5) return std::unexpected(std::string("head controller options: ") + name + " above 0.5 rad");
  }
  const BacklashEstimateOptions& be = o.backlash_estimate;
  for (const auto& [v, name] : {std::pair{be.max_rad, "backlash_estimate.max_rad"},
                                 std::pair{be.reversal_rad, "backlash_estimate.reversal_rad"},
                                 std::pair{be.engaged_rad, "backlash_estimate.engaged_rad"},
                                 std::pair{be.max_crossing_s, "backlash_estimate.max_crossing_s"},
                                 std::pair{be.quiet_body_radps, "backlash_estimate.quiet_body_radps"},
                                 std::pair{be.confirm_tolerance_rad, "backlash_estimate.confirm_tolerance_rad"},
                                 std::pair{be.max_reading_gap_s, "backlash_estimate.max_reading_gap_s"},
                                 std::pair{be.applied_fraction, "backlash_estimate.applied_fraction"}})
    if (auto ok = positive(v, name); !ok) return std::unexpected(ok.error());
  if (auto ok = non_negative(be.confirm_s, "backlash_estimate.confirm_s"); !ok) return std::unexpected(ok.error());
  if (auto ok = non_negative(be.min_applied_rad, "backlash_estimate.min_applied_rad"); !ok) return std::unexpected(ok.error());
  if (be.max_rad > 0.5) return std::unexpected("head controller options: backlash_estimate.max_rad above 0.5 rad");
  if (be.applied_fraction > 1) return std::unexpected("head controller options: backlash_estimate.applied_fraction above 1");
  if (be.window < 1 || be.window > BacklashEstimator::kMaxWindow || be.min_samples < 1 || be.min_samples > be.window)
    return std::unexpected("head controller options: backlash_estimate.window must be in [1, 31] and min_samples in [1, window]");
  if (o.safe_mode != ControlMode::Hold && o.safe_mode != ControlMode::Park)
    return std::unexpected("head controller options: safe_mode must be hold or park");
  if (!finite(o.mount.pan_origin_body) || !finite(o.mount.tilt_origin_pan) || !finite(o.mount.cam_offset_tilt) ||
      !finite(o.mount.cam_misalign_rad))
    return std::unexpected("head controller options: mount offsets and misalignment must be finite");
  return HeadController(o);
}

HeadController::HeadController(const HeadControllerOptions& o)
    // The IMU may run faster than the loop: room for 2 kHz over the history.
    : options_(o), watchdog_(o.watchdog), attitude_(o.history_s, std::max(o.rate_hz, 2000.0)), joint_rates_(o.joint_rates),
      pan_backlash_(o.backlash.pan_rad), tilt_backlash_(o.backlash.tilt_rad), pan_play_(o.backlash_estimate),
      tilt_play_(o.backlash_estimate) {}

void HeadController::emit(ControlOutput& out, const HeadEvent& e) {
  ++counters_.events;
  if (out.event_count < kMaxEventsPerStep) out.events[static_cast<std::size_t>(out.event_count++)] = e;
  else ++counters_.events_dropped;
}

void HeadController::ingest(const ControlInput& in) {
  bool new_gyro = false, new_head = false;
  double gyro_dt_s = 0;
  if (in.gyro && !(have_gyro_ && in.gyro->t_s == gyro_.t_s)) {
    if (!finite(in.gyro->t_s) || !finite(in.gyro->gyro_radps) || (have_gyro_ && in.gyro->t_s < gyro_.t_s)) {
      ++counters_.gyro_rejected;
    } else {
      gyro_dt_s = have_gyro_ ? in.gyro->t_s - gyro_.t_s : 0;
      attitude_.add(in.gyro->t_s, in.gyro->gyro_radps, options_.watchdog.imu_timeout_s);
      gyro_ = *in.gyro;
      have_gyro_ = true;
      new_gyro = true;
    }
  }
  if (in.head && !(have_head_ && in.head->t_s == head_.t_s)) {
    const JointState& h = *in.head;
    if (!finite(h.t_s) || !finite(h.angles.pan_rad) || !finite(h.angles.tilt_rad) || !finite(h.pan_rate_radps) ||
        !finite(h.tilt_rate_radps) || (have_head_ && h.t_s < head_.t_s)) {
      ++counters_.head_state_rejected;
    } else {
      head_ = h;
      have_head_ = true;
      new_head = true;
      joint_rates_.measured(h.t_s, {h.pan_rate_radps, h.tilt_rate_radps});
    }
  }
  if (new_gyro && have_head_) update_body_rate();
  measure_backlash(new_gyro, new_head, gyro_dt_s);
  if (in.target && !(have_target_ && in.target->t_s == target_t_s_)) {
    const TargetObservation& obs = *in.target;
    Eigen::Quaterniond inertial_R_cam;
    const double n = obs.target_cam.norm();
    // A prediction for "now" may be a little ahead of the newest gyro sample: allow up to the
    // IMU timeout (the watchdog catches longer gaps).
    if (!finite(obs.t_s) || !finite(obs.target_cam) || !(obs.target_cam.z() > 0) || !(n > 0) ||
        (have_target_ && obs.t_s < target_t_s_) || !attitude_.at(obs.t_s, inertial_R_cam, options_.watchdog.imu_timeout_s)) {
      ++counters_.target_rejected;
    } else {
      const Eigen::Vector3d dir = inertial_R_cam * (obs.target_cam / n);
      const double gap_s = obs.t_s - target_t_s_;
      if (have_target_ && !attitude_broken_ && gap_s > 1e-4 && gap_s <= options_.watchdog.target_timeout_s) {
        // The direction's rate between observations, low-passed (tracker noise is per frame).
        const Eigen::Vector3d raw = rotation_to(target_dir_, dir) / gap_s;
        const double k = std::min(1.0, gap_s / options_.target_rate_filter_s);
        target_rate_ += k * (raw - target_rate_);
        const double r = target_rate_.norm();
        if (r > options_.target_rate_max_radps) target_rate_ *= options_.target_rate_max_radps / r;
      } else {
        target_rate_.setZero();
      }
      target_dir_ = dir;
      attitude_broken_ = false;
      target_t_s_ = obs.t_s;
      target_arrival_t_s_ = last_t_s_;
      have_target_ = true;
    }
  }
}

HeadController::Resolved HeadController::resolve() const {
  const Fault f = watchdog_.faults();
  if (!have_head_) return {ControlMode::Startup, std::nullopt};
  if (has(f, Fault::BusOff)) return {options_.safe_mode, ModeReason::BusOff};
  if (has(f, Fault::HeadStateStale)) return {options_.safe_mode, ModeReason::HeadStateStale};
  const ControlMode r = requested_;
  if (r == ControlMode::Hold || r == ControlMode::Park) return {r, std::nullopt};
  if (has(f, Fault::ImuStale)) return {ControlMode::Hold, ModeReason::ImuStale};
  if (r == ControlMode::Fixate && has(f, Fault::TargetLost)) {
    if (last_t_s_ - watchdog_.target_lost_since_s() >= options_.watchdog.lost_to_hold_s)
      return {ControlMode::Hold, ModeReason::TrackingLostLong};
    return {ControlMode::Stabilise, ModeReason::TrackingLost};
  }
  return {r, std::nullopt};
}

// The commands restart from the head's measured angles and rates (within the limits).
void HeadController::command_from_head() {
  pan_cmd_ = {std::clamp(head_.angles.pan_rad, options_.pan.min_rad, options_.pan.max_rad),
              clamp_rate(head_.pan_rate_radps, options_.pan)};
  tilt_cmd_ = {std::clamp(head_.angles.tilt_rad, options_.tilt.min_rad, options_.tilt.max_rad),
               clamp_rate(head_.tilt_rate_radps, options_.tilt)};
  pan_backlash_.reset(pan_cmd_.angle_rad);
  tilt_backlash_.reset(tilt_cmd_.angle_rad);
  pan_play_.restart_leg();
  tilt_play_.restart_leg();
}

void HeadController::enter(ControlMode mode, ModeReason reason, double t_s, ControlOutput& out) {
  if (mode_ == ControlMode::Startup) command_from_head();  // the first command starts where the head is
  blend_t0_s_ = t_s;
  blend_from_ = {pan_cmd_.rate_radps, tilt_cmd_.rate_radps};
  switch (mode) {
    case ControlMode::Stabilise:
      reference_dir_ = attitude_.newest() * Eigen::Vector3d::UnitZ();
      break;
    case ControlMode::Hold:
      hold_ = {stopping_angle(pan_cmd_, options_.pan), stopping_angle(tilt_cmd_, options_.tilt)};
      break;
    case ControlMode::Park:
      parked_reported_ = false;
      break;
    default:
      break;
  }
  HeadEvent e;
  e.t_s = t_s;
  e.kind = EventKind::ModeChanged;
  e.from = mode_;
  e.to = mode;
  e.reason = reason;
  emit(out, e);
  mode_ = mode;
}

void HeadController::update_body_rate() {
  // Camera rate (camera axes) = body rate + J q_dot: the body rate is what the gyro sees minus
  // what the joints add.
  const Eigen::Matrix<double, 3, 2> J = joint_axes_cam(options_.mount, head_.angles);
  const Eigen::Vector3d raw = gyro_.gyro_radps - J * joint_rates_.at(gyro_.t_s);
  const double dt = gyro_.t_s - body_rate_t_s_;
  Eigen::Vector3d body = raw;
  if (have_body_rate_ && dt > 0 && dt <= options_.watchdog.imu_timeout_s) {
    body = body_rate_cam_ + dt / (options_.body_rate_filter_s + dt) * (raw - body_rate_cam_);
    const double k = std::min(1.0, dt / options_.rate_lead_filter_s);
    body_accel_cam_ += k * ((body - body_rate_cam_) / dt - body_accel_cam_);
  } else {
    body_accel_cam_.setZero();
  }
  body_rate_cam_ = body;
  body_rate_t_s_ = gyro_.t_s;
  have_body_rate_ = true;
}

// The play of each gear, from the gyro's rate about the joints and the encoder's motor angles
// (backlash_estimate.h); a wider band than calibrated goes to the compensation.
void HeadController::measure_backlash(bool new_gyro, bool new_head, double gyro_dt_s) {
  if (!options_.backlash_estimate.enabled || !have_head_ || !have_gyro_ || (!new_gyro && !new_head)) return;
  const Eigen::Matrix2d A = joint_axes_cam(options_.mount, head_.angles).topRows<2>();
  // Near +-90 deg tilt the pan axis lines up with the optical axis: no joint-space split there.
  if (!(std::abs(A.determinant()) > 0.2)) return;
  const Eigen::Matrix2d A_inv = A.inverse();
  if (new_gyro) {
    if (gyro_dt_s > options_.watchdog.imu_timeout_s) {  // a gap: the camera's turning meanwhile is unknown
      pan_play_.restart_leg();
      tilt_play_.restart_leg();
    } else {
      const Eigen::Vector2d camera_joint = A_inv * gyro_.gyro_radps.head<2>();
      pan_play_.camera_rate(camera_joint.x(), gyro_dt_s);
      tilt_play_.camera_rate(camera_joint.y(), gyro_dt_s);
    }
  }
  if (new_head && have_body_rate_) {
    const Eigen::Vector2d body_joint = A_inv * body_rate_cam_.head<2>();
    pan_play_.motor_angle(head_.t_s, head_.angles.pan_rad, body_joint.x());
    tilt_play_.motor_angle(head_.t_s, head_.angles.tilt_rad, body_joint.y());
    pan_backlash_.set_band(pan_play_.band_rad(options_.backlash.pan_rad), pan_cmd_.angle_rad);
    tilt_backlash_.set_band(tilt_play_.band_rad(options_.backlash.tilt_rad), tilt_cmd_.angle_rad);
    counters_.backlash_samples = pan_play_.samples() + tilt_play_.samples();
    counters_.backlash_samples_rejected = pan_play_.rejected() + tilt_play_.rejected();
  }
}

Eigen::Vector2d HeadController::camera_rate_law(const Eigen::Vector2d& camera_rate_xy_radps) const {
  // Choose q_dot so the camera's x and y rates become the wanted ones against the (predicted)
  // body rate.
  const Eigen::Matrix<double, 3, 2> J = joint_axes_cam(options_.mount, head_.angles);
  const Eigen::Vector3d body_cam = body_rate_cam_ + options_.rate_lead_s * body_accel_cam_;
  const Eigen::Vector2d b = camera_rate_xy_radps - body_cam.head<2>();
  const Eigen::Matrix2d A = J.topRows<2>();
  // |det A| = cos(tilt) for the nominal mount: only near +-90 deg tilt (outside the default
  // limits) does the pan axis line up with the optical axis; damp the solve there.
  if (std::abs(A.determinant()) > 0.2) return A.inverse() * b;
  constexpr double lambda2 = 0.04;
  return (A.transpose() * A + lambda2 * Eigen::Matrix2d::Identity()).inverse() * A.transpose() * b;
}

Eigen::Vector2d HeadController::desired_rates(double t_s, ControlOutput& out) {
  const Eigen::Quaterniond& inertial_R_cam = attitude_.newest();
  auto joint_p = [](double target, const JointCommand& c, double gain, double max_rate) {
    return std::clamp(gain * (target - c.angle_rad), -max_rate, max_rate);
  };
  switch (mode_) {
    case ControlMode::Startup:
      return Eigen::Vector2d::Zero();
    case ControlMode::Stabilise: {
      const Eigen::Vector3d d_cam = inertial_R_cam.conjugate() * reference_dir_;
      const Eigen::Vector3d err = rotation_to(Eigen::Vector3d::UnitZ(), d_cam);
      return camera_rate_law(options_.stabilise_gain_per_s * err.head<2>());
    }
    case ControlMode::Fixate: {
      // The target direction now: carried from its observation time with its filtered rate.
      const double ahead_s = std::clamp(t_s - target_t_s_, 0.0, options_.history_s);
      const Eigen::Vector3d turn = target_rate_ * ahead_s;
      const Eigen::Vector3d dir =
          turn.norm() > 1e-12 ? Eigen::Vector3d(Eigen::AngleAxisd(turn.norm(), turn.normalized()) * target_dir_) : target_dir_;
      const Eigen::Vector3d d_cam = inertial_R_cam.conjugate() * dir;
      const Eigen::Vector3d err = rotation_to(Eigen::Vector3d::UnitZ(), d_cam);
      out.target_error_rad = err.norm();
      const Eigen::Vector2d feedback = clamp_norm(options_.fixate_gain_per_s * err.head<2>(), options_.fixate_max_rate_radps);
      const Eigen::Vector3d ff = inertial_R_cam.conjugate() * target_rate_;
      return camera_rate_law(feedback + ff.head<2>());
    }
    case ControlMode::Hold:
      return {joint_p(hold_.pan_rad, pan_cmd_, options_.hold_gain_per_s, options_.hold_max_rate_radps),
              joint_p(hold_.tilt_rad, tilt_cmd_, options_.hold_gain_per_s, options_.hold_max_rate_radps)};
    case ControlMode::Park: {
      const JointAngles& p = options_.park;
      if (!parked_reported_ && std::abs(pan_cmd_.angle_rad - p.pan_rad) < options_.park_tolerance_rad &&
          std::abs(tilt_cmd_.angle_rad - p.tilt_rad) < options_.park_tolerance_rad &&
          std::abs(pan_cmd_.rate_radps) < 0.01 && std::abs(tilt_cmd_.rate_radps) < 0.01) {
        parked_reported_ = true;
        HeadEvent e;
        e.t_s = t_s;
        e.kind = EventKind::Parked;
        e.from = e.to = ControlMode::Park;
        emit(out, e);
      }
      return {joint_p(p.pan_rad, pan_cmd_, options_.hold_gain_per_s, options_.park_rate_radps),
              joint_p(p.tilt_rad, tilt_cmd_, options_.hold_gain_per_s, options_.park_rate_radps)};
    }
  }
  return Eigen::Vector2d::Zero();
}

ControlOutput HeadController::step(const ControlInput& in) {
  ControlOutput out;
  ++counters_.steps;
  const double dt = advance_clock(in.t_s);
  const double t = last_t_s_;
  ingest(in);
  const bool request_changed = requested_ != last_requested_;
  last_requested_ = requested_;
  const FaultChange change = supervise(t, in.bus == hw::CanBusState::BusOff, out);
  const Resolved r = resolve();
  if (r.mode != mode_) {
    ModeReason reason = ModeReason::Recovered;
    if (r.fallback) reason = *r.fallback;
    else if (request_changed) reason = ModeReason::Requested;
    else if (mode_ == ControlMode::Startup) reason = ModeReason::HeadStateArrived;
    else if (has(change.cleared, Fault::TargetLost)) reason = ModeReason::TrackingRecovered;
    enter(r.mode, reason, t, out);
  }
  bound_following_error();
  const Eigen::Vector2d output_rates = shape_commands(t, dt, out);
  encode_command(t, output_rates, out);
  return out;
}

// The step's dt: 0 for a first, non-finite or non-advancing time (counted), else at most five
// periods (a stalled caller must not make one step jump).
double HeadController::advance_clock(double t_s) {
  double dt = 0;
  if (!finite(t_s) || (started_ && !(t_s > last_t_s_))) {
    ++counters_.time_not_advancing;
  } else {
    if (started_) dt = std::min(t_s - last_t_s_, 5.0 / options_.rate_hz);
    started_ = true;
    last_t_s_ = t_s;
  }
  return dt;
}

// The watchdog over the inputs' ages: fault events, and what a raised or cleared fault resets.
FaultChange HeadController::supervise(double t, bool bus_off, ControlOutput& out) {
  WatchdogInput w;
  w.t_s = t;
  w.have_gyro = have_gyro_;
  w.last_gyro_t_s = gyro_.t_s;
  w.have_head_state = have_head_;
  w.last_head_state_t_s = head_.t_s;
  w.bus_off = bus_off;
  w.fixating = requested_ == ControlMode::Fixate;
  w.have_target = have_target_;
  w.last_target_t_s = target_arrival_t_s_;
  const FaultChange change = watchdog_.update(w);
  for (int bit = 0; bit < 4; ++bit) {
    const Fault f = static_cast<Fault>(1u << bit);
    if (!has(change.raised, f) && !has(change.cleared, f)) continue;
    HeadEvent e;
    e.t_s = t;
    e.kind = has(change.raised, f) ? EventKind::FaultRaised : EventKind::FaultCleared;
    e.from = e.to = mode_;
    e.fault = f;
    emit(out, e);
  }
  // The gyro attitude restarts after a gap without knowing how the camera turned meanwhile:
  // a target direction from before it is not comparable with one after.
  if (has(change.raised, Fault::ImuStale)) {
    attitude_broken_ = true;
    target_rate_.setZero();
  }
  // After a bus-off or a silent head the head has braked on its own (command timeout): restart
  // the command from where it is instead of from where it was told to be.
  if (mode_ != ControlMode::Startup && (has(change.cleared, Fault::BusOff) || has(change.cleared, Fault::HeadStateStale))) {
    joint_rates_.reset();
    command_from_head();
  }
  return change;
}

// A joint that does not follow (stuck, blocked, slower than commanded) must not wind up the
// commanded angle: the head would lunge when it frees.
void HeadController::bound_following_error() {
  if (mode_ == ControlMode::Startup || has(watchdog_.faults(), Fault::HeadStateStale)) return;
  auto bound = [&](JointCommand& c, double measured) {
    const double e = c.angle_rad - measured;
    if (std::abs(e) > options_.max_following_error_rad) {
      c.angle_rad = measured + std::copysign(options_.max_following_error_rad, e);
      ++counters_.following_error_clamped;
    }
  };
  bound(pan_cmd_, head_.angles.pan_rad);
  bound(tilt_cmd_, head_.angles.tilt_rad);
  pan_backlash_.place(pan_cmd_.angle_rad);
  tilt_backlash_.place(tilt_cmd_.angle_rad);
}

// The mode's desired rates, blended after a switch, through the backlash inverse and the
// joints' limits into the commands. Returns the output (after-backlash) joint rates.
Eigen::Vector2d HeadController::shape_commands(double t, double dt, ControlOutput& out) {
  out.target_error_rad = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector2d rates = desired_rates(t, out);
  Eigen::Vector2d output_rates = Eigen::Vector2d::Zero();
  if (mode_ == ControlMode::Startup) return output_rates;
  if (options_.switch_blend_s > 0) {
    const double a = std::clamp((t - blend_t0_s_) / options_.switch_blend_s, 0.0, 1.0);
    rates = (1 - a) * blend_from_ + a * rates;
  }
  // The camera-rate laws want output rates: through the dead-band inverse to motor rates. Hold
  // and Park steer the joint angles the encoder measures; the band's model still follows.
  if (mode_ == ControlMode::Stabilise || mode_ == ControlMode::Fixate) {
    rates = {pan_backlash_.motor_rate(rates.x(), pan_cmd_, options_.pan, dt),
             tilt_backlash_.motor_rate(rates.y(), tilt_cmd_, options_.tilt, dt)};
  }
  pan_cmd_ = shape(options_.pan, pan_cmd_, rates.x(), dt, out.pan_limits);
  tilt_cmd_ = shape(options_.tilt, tilt_cmd_, rates.y(), dt, out.tilt_limits);
  output_rates = {pan_backlash_.follow(pan_cmd_, dt), tilt_backlash_.follow(tilt_cmd_, dt)};
  counters_.backlash_reversals = pan_backlash_.reversals() + tilt_backlash_.reversals();
  for (std::uint8_t hits : {out.pan_limits, out.tilt_limits}) {
    counters_.rate_limited += (hits & kLimitRate) != 0;
    counters_.accel_limited += (hits & kLimitAccel) != 0;
    counters_.braking_limited += (hits & kLimitBraking) != 0;
    counters_.position_limited += (hits & kLimitPosition) != 0;
  }
  return output_rates;
}

// The command on the wire (withheld at start-up and during bus-off), and its counter.
void HeadController::encode_command(double t, Eigen::Vector2d output_rates, ControlOutput& out) {
  out.mode = mode_;
  out.requested = requested_;
  out.faults = watchdog_.faults();
  out.dispatch = (mode_ == ControlMode::Startup || has(out.faults, Fault::BusOff)) ? Dispatch::Withhold : Dispatch::Send;
  firmware_iface::HeadCommand& c = out.command;
  c.mode = firmware_iface::HeadMode::Position;
  c.pan_rad = wire_angle(pan_cmd_.angle_rad, options_.pan, counters_.encode_clipped);
  c.tilt_rad = wire_angle(tilt_cmd_.angle_rad, options_.tilt, counters_.encode_clipped);
  c.pan_rate_radps = wire_rate(pan_cmd_.rate_radps, counters_.encode_clipped);
  c.tilt_rate_radps = wire_rate(tilt_cmd_.rate_radps, counters_.encode_clipped);
  c.counter = counter_;
  if (out.dispatch == Dispatch::Send) {
    // A joint without backlash: its output moves with the motor, at the rate on the wire.
    if (!pan_backlash_.active()) output_rates.x() = c.pan_rate_radps;
    if (!tilt_backlash_.active()) output_rates.y() = c.tilt_rate_radps;
    joint_rates_.sent(t, {c.pan_rate_radps, c.tilt_rate_radps}, output_rates);
    counter_ = static_cast<std::uint8_t>((counter_ + 1) & 0x0f);
    ++counters_.sent;
  } else {
    ++counters_.withheld;
  }
}

}  // namespace epichead::head
