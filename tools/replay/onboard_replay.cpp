#include "replay/onboard_replay.h"

#include <cmath>
#include <cstdio>

namespace epichead::tools::replay {

namespace {

constexpr double kDeg = 180.0 / M_PI;
constexpr std::size_t kKeptEvents = 12;

// Per-axis RMS 1-sigma of a 3x3 covariance block.
double sigma(const fusion::ErrorCovariance& P, int at) { return std::sqrt(std::max(0.0, P.block<3, 3>(at, at).trace() / 3)); }

}  // namespace

std::expected<std::unique_ptr<OnboardReplay>, std::string> OnboardReplay::create(const OnboardReplayOptions& o) {
  if (!(o.frame_period_s > 0) || !(o.restart_period_s > o.frame_period_s) || !(o.control_rate_hz > 0))
    return std::unexpected("replay: frame period, restart period (longer) and control rate must be positive");
  auto predictor = fusion::Predictor::create(o.predictor);
  if (!predictor) return std::unexpected("replay: predictor: " + predictor.error());
  auto controller = head::HeadController::create(o.controller);
  if (!controller) return std::unexpected("replay: head controller: " + controller.error());
  controller->request(head::ControlMode::Stabilise);
  return std::unique_ptr<OnboardReplay>(new OnboardReplay(o, std::move(*predictor), std::move(*controller)));
}

OnboardReplay::OnboardReplay(const OnboardReplayOptions& options, fusion::Predictor predictor, head::HeadController controller)
    : options_(options), predictor_(std::move(predictor)), controller_(std::move(controller)) {}

void OnboardReplay::try_start(double t_s) {
  // The reference pose is exact by definition: a tiny covariance (0.1 mm, 0.006 deg).
  fusion::Matrix6d cov = fusion::Matrix6d::Identity() * 1e-8;
  const auto v = predictor_.add_vision(t_s, reference_, cov).verdict;
  if (v != fusion::VisionVerdict::Initialised && v != fusion::VisionVerdict::Applied) return;
  running_ = true;
  run_start_t_s_ = t_s;
  frame_noted_ = second_noted_ = false;
  if (started_at_s_ < 0) started_at_s_ = t_s;
}

void OnboardReplay::note_growth(double t_s) {
  const double since = t_s - run_start_t_s_;
  const fusion::ErrorCovariance& P = predictor_.covariance();
  if (!frame_noted_ && since >= options_.frame_period_s) {
    frame_noted_ = true;
    frame_rot_sum_ += sigma(P, fusion::err::theta);
    frame_pos_sum_ += sigma(P, fusion::err::p);
    ++frame_n_;
  }
  if (!second_noted_ && since >= options_.restart_period_s) {
    second_noted_ = true;
    second_rot_sum_ += sigma(P, fusion::err::theta);
    second_pos_sum_ += sigma(P, fusion::err::p);
    ++second_n_;
  }
}

void OnboardReplay::add_imu(const ImuObservation& o) {
  if (first_t_s_ < 0) first_t_s_ = o.t_s;
  ++imu_fed_;
  const double t_dev = o.device_us >= 0 ? static_cast<double>(o.device_us) * 1e-6 : o.t_s;
  const Eigen::Vector3d gyro(o.gyro_radps[0], o.gyro_radps[1], o.gyro_radps[2]);
  const Eigen::Vector3d accel(o.accel_mps2[0], o.accel_mps2[1], o.accel_mps2[2]);
  const fusion::ImuVerdict v = predictor_.add_imu({t_dev, gyro, accel});
  if (!running_) {
    try_start(t_dev);
  } else if (v == fusion::ImuVerdict::Accepted) {
    note_growth(t_dev);
    if (const auto x = predictor_.state()) {
      const Eigen::Matrix3d& R = x->obj_R_cam;
      const Eigen::Vector3d axis = R.col(2);
      attitude_.add(o.t_s, {std::atan2(R(1, 0), R(0, 0)) * kDeg,
                            std::atan2(-axis.y(), std::hypot(axis.x(), axis.z())) * kDeg,
                            std::atan2(axis.x(), axis.z()) * kDeg});
      if (t_dev - run_start_t_s_ >= options_.restart_period_s) {
        // Start again from where it is, so the IMU-only run stays short (as between frames).
        Eigen::Isometry3d obj_T_cam = Eigen::Isometry3d::Identity();
        obj_T_cam.linear() = R;
        obj_T_cam.translation() = x->obj_p_cam;
        reference_ = obj_T_cam.inverse();
        reference_.translation().setZero();  // position is not observable without vision
        predictor_.reset();
        running_ = false;
        ++restarts_;
        try_start(t_dev);
      }
    }
  }
  // The controller sees the gyro on the log's (receive) clock, in camera axes.
  tick_until(o.t_s);
  gyro_ = {o.t_s, options_.predictor.mount.cam_R_imu * gyro};  // the controller counts what it rejects
  have_gyro_ = true;
}

void OnboardReplay::add_head_state(double t_s, const firmware_iface::HeadState& s) {
  if (first_t_s_ < 0) first_t_s_ = t_s;
  tick_until(t_s);
  head_ = head::joint_state_from(s, t_s);
  have_head_ = true;
}

void OnboardReplay::tick_until(double t_s) {
  if (!std::isfinite(t_s)) return;
  if (!ticking_) {
    ticking_ = true;
    next_tick_s_ = t_s;
  }
  const double period = 1.0 / options_.control_rate_hz;
  // A log with a long silence is stepped over at most one second of ticks (the watchdog has
  // long tripped by then); the rest of the gap is skipped.
  if (t_s - next_tick_s_ > 1.0) next_tick_s_ = t_s - 1.0;
  while (next_tick_s_ <= t_s) {
    head::ControlInput in;
    in.t_s = next_tick_s_;
    if (have_gyro_) in.gyro = gyro_;
    if (have_head_) in.head = head_;
    const head::ControlOutput out = controller_.step(in);
    ++ticks_;
    for (int i = 0; i < out.event_count; ++i) {
      const head::HeadEvent& e = out.events[static_cast<std::size_t>(i)];
      if (e.kind != head::EventKind::FaultRaised && e.kind != head::EventKind::FaultCleared) continue;
      const bool raised = e.kind == head::EventKind::FaultRaised;
      if (e.fault == head::Fault::ImuStale) {
        if (raised) {
          ++imu_stale_raised_;
          imu_stale_since_ = e.t_s;
        } else if (imu_stale_since_ >= 0) {
          imu_stale_total_s_ += e.t_s - imu_stale_since_;
          imu_stale_since_ = -1;
        }
      }
      if (e.fault == head::Fault::HeadStateStale && raised) ++head_stale_raised_;
      if (first_events_.size() < kKeptEvents)
        first_events_.push_back({e.t_s, std::string(head::to_string(e.kind)) + " " + head::to_string(e.fault)});
    }
    next_tick_s_ += period;
  }
}

void OnboardReplay::finish() {
  if (imu_stale_since_ >= 0 && ticking_) {
    imu_stale_total_s_ += next_tick_s_ - imu_stale_since_;
    imu_stale_since_ = -1;
  }
}

nlohmann::json OnboardReplay::fusion_json() const {
  const fusion::PredictorCounters c = predictor_.status(0).counters;
  nlohmann::json j{{"imu_samples_fed", imu_fed_},
                   {"accepted", c.imu_accepted},
                   {"rejected", {{"non_finite", c.imu_non_finite},
                                 {"saturated", c.imu_saturated},
                                 {"out_of_order", c.imu_out_of_order},
                                 {"duplicate", c.imu_duplicate},
                                 {"time_jump", c.imu_time_jump}}},
                   {"stream_restarts", c.imu_restarts},
                   {"dropouts", c.dropouts},
                   {"dropout_total_s", c.dropout_total_s},
                   {"started_at_s", started_at_s_},
                   {"restarts", restarts_}};
  if (frame_n_ > 0)
    j["growth_after_frame"] = {{"period_s", options_.frame_period_s},
                               {"orientation_deg_1sigma", frame_rot_sum_ / frame_n_ * kDeg},
                               {"position_mm_1sigma", frame_pos_sum_ / frame_n_ * 1e3}};
  if (second_n_ > 0)
    j["growth_after_restart_period"] = {{"period_s", options_.restart_period_s},
                                        {"orientation_deg_1sigma", second_rot_sum_ / second_n_ * kDeg},
                                        {"position_mm_1sigma", second_pos_sum_ / second_n_ * 1e3}};
  if (started_at_s_ < 0) j["note"] = "never started: no accelerometer samples to take gravity from";
  return j;
}

nlohmann::json OnboardReplay::controller_json() const {
  const head::HeadCounters& c = controller_.counters();
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : first_events_) events.push_back({{"t_s", e.t_s}, {"event", e.what}});
  return {{"ticks", ticks_},
          {"gyro_rejected", c.gyro_rejected},
          {"head_state_rejected", c.head_state_rejected},
          {"imu_stale_raised", imu_stale_raised_},
          {"imu_stale_total_s", imu_stale_total_s_},
          {"head_state_stale_raised", head_stale_raised_},
          {"first_events", events}};
}

std::string OnboardReplay::text() const {
  if (imu_fed_ == 0 && !have_head_) return "onboard estimators: not run (no IMU samples or head states of ours in the log)\n";
  const fusion::PredictorCounters c = predictor_.status(0).counters;
  char buf[768];
  int n = std::snprintf(buf, sizeof buf,
                        "fusion predictor: %llu samples fed, %llu accepted; rejected %llu non-finite, %llu saturated, "
                        "%llu out of order, %llu duplicate, %llu time jumps; %llu dropouts (%.3f s)\n",
                        static_cast<unsigned long long>(imu_fed_), static_cast<unsigned long long>(c.imu_accepted),
                        static_cast<unsigned long long>(c.imu_non_finite), static_cast<unsigned long long>(c.imu_saturated),
                        static_cast<unsigned long long>(c.imu_out_of_order), static_cast<unsigned long long>(c.imu_duplicate),
                        static_cast<unsigned long long>(c.imu_time_jump), static_cast<unsigned long long>(c.dropouts),
                        c.dropout_total_s);
  std::string out(buf, static_cast<std::size_t>(std::max(0, n)));
  if (frame_n_ > 0) {
    n = std::snprintf(buf, sizeof buf,
                      "  prediction without vision: 1-sigma %.3f deg / %.2f mm after %.0f ms, %.2f deg / %.0f mm after %.1f s\n",
                      frame_rot_sum_ / frame_n_ * kDeg, frame_pos_sum_ / frame_n_ * 1e3, options_.frame_period_s * 1e3,
                      second_n_ ? second_rot_sum_ / second_n_ * kDeg : NAN, second_n_ ? second_pos_sum_ / second_n_ * 1e3 : NAN,
                      options_.restart_period_s);
    out.append(buf, static_cast<std::size_t>(std::max(0, n)));
  }
  n = std::snprintf(buf, sizeof buf,
                    "head controller watchdog: IMU stale raised %llu times (%.3f s in all), head state stale %llu times\n",
                    static_cast<unsigned long long>(imu_stale_raised_), imu_stale_total_s_,
                    static_cast<unsigned long long>(head_stale_raised_));
  out.append(buf, static_cast<std::size_t>(std::max(0, n)));
  return out;
}

}  // namespace epichead::tools::replay
