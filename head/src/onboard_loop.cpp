#include "epichead/head/onboard_loop.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <variant>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/protocol.h"
#include "epichead/head/target_observation.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/window_image.h"
#include "recent_samples.h"

namespace epichead::head {
namespace {

namespace fw = firmware_iface;
using WallClock = std::chrono::steady_clock;

double wall_ms_since(WallClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(WallClock::now() - t0).count();
}

// A camera buffer as an 8-bit grey or BGR image: wrapped without a copy, or converted into
// `scratch` (sized once) for YUYV and RGB. Empty for formats the tracker cannot read (MJPEG).
cv::Mat as_image(const hw::CameraFrame& f, cv::Mat& scratch) {
  auto* data = const_cast<std::uint8_t*>(f.data);  // read only: WindowImage::assign copies out
  const auto stride = static_cast<std::size_t>(f.stride_bytes);
  switch (f.format) {
    case hw::PixelFormat::Gray8: return {f.height, f.width, CV_8UC1, data, stride};
    case hw::PixelFormat::Bgr24: return {f.height, f.width, CV_8UC3, data, stride};
    case hw::PixelFormat::Rgb24: cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC3, data, stride), scratch, cv::COLOR_RGB2BGR); return scratch;
    case hw::PixelFormat::Yuyv: cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC2, data, stride), scratch, cv::COLOR_YUV2BGR_YUYV); return scratch;
    default: return {};
  }
}

// The centre of the model's vertices: what fixation keeps in the middle of the image.
Eigen::Vector3d model_centre(const vision::CadModel& model) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& v : model.vertices) sum += v;
  return model.vertices.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(model.vertices.size()));
}

}  // namespace

struct OnboardLoop::Impl {
  Impl(const vision::CadModel& m, const vision::Camera& cam, const OnboardOptions& o, const OnboardPorts& p,
       fusion::Predictor pred, HeadController ctrl)
      : model(&m), camera(cam), options(o), ports(p), tracker(m, cam, o.tracker), predictor(std::move(pred)),
        controller(std::move(ctrl)), target_point_obj(model_centre(m)) {}

  const vision::CadModel* model;
  vision::Camera camera;
  OnboardOptions options;
  OnboardPorts ports;
  vision::ModelTracker tracker;
  fusion::Predictor predictor;
  HeadController controller;
  Eigen::Vector3d target_point_obj;
  DeviceClockSync imu_clock;
  ImuFrameAssembler assembler;
  std::optional<fw::CandumpWriter> log;
  std::FILE* diagnostics = nullptr;
  vision::WindowImage image;
  cv::Mat converted;  // YUYV / RGB frames converted to BGR (reused)
  vision::FrameReport report;

  // Initial pose and the last good one: where windows go while the predictor has nothing.
  Eigen::Isometry3d last_good = Eigen::Isometry3d::Identity();
  double init_t_s = 0;
  bool init_pending = false;

  // A vision result waiting for its publication time (modelled processing).
  struct Pending {
    bool active = false;
    double publish_t_s = 0, exposure_t_s = 0, taken_t_s = 0;
    Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
    Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
    vision::TrackStatus status = vision::TrackStatus::Lost;
  } pending;
  std::optional<double> target_exposure_t_s;  // exposure time of the target given to the controller, until a command uses it
  double target_publish_t_s = 0;              // when that target was published (the processing done)

  std::optional<GyroReading> gyro;
  std::optional<JointState> joints;
  std::optional<TargetObservation> target;
  hw::CanBusState bus_state = hw::CanBusState::ErrorActive;
  vision::TrackStatus last_status = vision::TrackStatus::Lost;

  OnboardSummary summary;
  // The last minutes of each timing, for the summary's percentiles.
  RecentSamples track_ms{1 << 14}, tick_ms{1 << 18}, latency_ms{1 << 14}, frame_age_ms{1 << 14}, overhead_ms{1 << 14};
  double next_sync_s = 0, next_diag_s = 0;
  std::uint64_t heartbeats = 0;

  void record(const fw::StampedCanFrame& f, fw::CanDirection dir) {
    if (log && log->write(f, options.candump_iface, dir)) ++summary.frames_logged;
  }
  void send(const fw::CanFrame& frame, double now_s) {
    if (auto ok = ports.bus->send(frame); !ok) {
      ++summary.send_failures;
      return;
    }
    record({static_cast<std::int64_t>(std::llround(now_s * 1e6)), frame}, fw::CanDirection::Transmitted);
  }

  void drain_bus(double now_s) {
    fw::StampedCanFrame f;
    for (;;) {
      const hw::CanReceive r = ports.bus->receive(f, 0);
      if (r == hw::CanReceive::Timeout) break;
      if (r == hw::CanReceive::Error) {
        ++summary.bus_errors;
        break;
      }
      record(f, fw::CanDirection::Received);
      if (f.frame.error()) continue;
      auto m = fw::decode(f.frame);
      if (!m) {
        (m.error().kind == fw::WireErrorKind::UnknownId ? summary.unknown_frames : summary.undecodable_frames) += 1;
        continue;
      }
      std::visit(
          [&](const auto& msg) {
            using T = std::decay_t<decltype(msg)>;
            if constexpr (std::is_same_v<T, fw::ImuGyro>) {
              if (auto s = assembler.on_gyro(msg, now_s, imu_clock)) on_imu(*s);
            } else if constexpr (std::is_same_v<T, fw::ImuAccel>) {
              if (auto s = assembler.on_accel(msg, now_s, imu_clock)) on_imu(*s);
            } else if constexpr (std::is_same_v<T, fw::HeadState>) {
              joints = JointState{now_s, JointAngles{msg.pan_rad, msg.tilt_rad}, msg.pan_rate_radps, msg.tilt_rate_radps};
            } else if constexpr (std::is_same_v<T, fw::TimeSyncReply>) {
              if (msg.node == fw::kNodeImu) imu_clock.on_reply(msg, now_s);
            } else if constexpr (std::is_same_v<T, fw::Heartbeat>) {
              ++heartbeats;
            }
          },
          *m);
    }
    bus_state = ports.bus->stats().state;
  }

  void on_imu(const fusion::ImuSample& s) {
    const fusion::ImuVerdict v = predictor.add_imu(s);
    if (v == fusion::ImuVerdict::Accepted || v == fusion::ImuVerdict::Buffered) ++summary.imu_samples;
    else ++summary.imu_rejected;
    if (std::isfinite(s.gyro_radps.sum())) gyro = GyroReading{s.t_s, s.gyro_radps};
  }

  void take_frame(double now_s, const FrameHook& hook) {
    if (pending.active) return;  // one frame in processing at a time (the camera queues the rest)
    hw::CameraFrame frame;
    const hw::CameraRead r = ports.camera->next_frame(frame, 0);
    if (r == hw::CameraRead::Lost) ++summary.camera_lost;
    if (r != hw::CameraRead::Frame) return;
    const cv::Mat mat = as_image(frame, converted);
    if (mat.empty() || !image.assign(mat)) {
      ++summary.unreadable_frames;
      return;
    }
    const double exposure = frame.t_s;
    if (init_pending) {
      const auto v = predictor.add_vision(init_t_s, last_good, vision::initial_pose_covariance()).verdict;
      init_pending = v != fusion::VisionVerdict::Initialised && v != fusion::VisionVerdict::Applied;
    }
    const auto prediction = predictor.predict(exposure);
    const Eigen::Isometry3d predicted = prediction ? prediction->cam_T_obj : last_good;
    const auto t0 = WallClock::now();
    tracker.track(image, predicted, report);
    const double ms = wall_ms_since(t0);
    track_ms.push(ms);
    ++summary.frames;
    (report.status == vision::TrackStatus::Lost ? summary.lost : summary.tracked) += 1;
    frame_age_ms.push(1e3 * (now_s - exposure));
    pending = {true, options.processing_s >= 0 ? now_s + options.processing_s : ports.clock->now_s(), exposure, now_s,
               report.cam_T_obj, report.covariance, report.status};
    if (hook) hook({summary.frames - 1, exposure, pending.publish_t_s, predicted, &report, &tracker, &frame});
  }

  void publish(double now_s) {
    if (!pending.active || now_s < pending.publish_t_s) return;
    pending.active = false;
    last_status = pending.status;
    if (pending.status == vision::TrackStatus::Lost) return;  // the controller's watchdog sees the target go stale
    last_good = pending.cam_T_obj;
    predictor.add_vision(pending.exposure_t_s, pending.cam_T_obj, vision::kTrackedPoseCovarianceInflation * pending.covariance);
    target = target_from_pose(pending.exposure_t_s, pending.cam_T_obj, target_point_obj);
    target_exposure_t_s = pending.exposure_t_s;
    target_publish_t_s = pending.publish_t_s;
  }

  void diagnose(double now_s, const ControlOutput& out) {
    if (!diagnostics) return;
    for (int i = 0; i < out.event_count; ++i) {
      const HeadEvent& e = out.events[static_cast<std::size_t>(i)];
      nlohmann::json j{{"t_s", e.t_s}, {"event", to_string(e.kind)}};
      if (e.kind == EventKind::ModeChanged) {
        j["from"] = to_string(e.from);
        j["to"] = to_string(e.to);
        j["reason"] = to_string(e.reason);
      } else if (e.kind != EventKind::Parked) {
        j["fault"] = to_string(e.fault);
      }
      std::fprintf(diagnostics, "%s\n", j.dump().c_str());
    }
    if (now_s < next_diag_s) return;
    next_diag_s = now_s + options.diagnostics_period_s;
    const auto st = predictor.status(now_s);
    const nlohmann::json j{{"t_s", now_s},
                           {"mode", to_string(out.mode)},
                           {"faults", static_cast<int>(out.faults)},
                           {"tracking", vision::to_string(last_status)},
                           {"frames", summary.frames},
                           {"lost", summary.lost},
                           {"imu_samples", summary.imu_samples},
                           {"predictor_coasting", st.coasting},
                           {"commands_sent", summary.commands_sent},
                           {"bus_state", hw::to_string(bus_state)},
                           {"target_error_deg", std::isfinite(out.target_error_rad) ? out.target_error_rad * 180 / M_PI : -1.0},
                           {"clock_round_trip_ms", imu_clock.round_trip_s() * 1e3}};
    std::fprintf(diagnostics, "%s\n", j.dump().c_str());
  }

  void tick(double now_s, const FrameHook& hook) {
    const auto t0 = WallClock::now();
    if (now_s >= next_sync_s) {
      next_sync_s = now_s + options.time_sync_period_s;
      if (auto frame = fw::encode(imu_clock.make_request(now_s))) send(frame->frame, now_s);
    }
    drain_bus(now_s);
    publish(now_s);
    take_frame(now_s, hook);
    publish(now_s);  // processing_s == 0 publishes at once
    ControlInput in;
    in.t_s = now_s;
    in.gyro = gyro;
    in.head = joints;
    in.bus = bus_state;
    in.target = target;
    const ControlOutput out = controller.step(in);
    if (out.dispatch == Dispatch::Send) {
      if (auto frame = fw::encode(out.command)) {
        send(frame->frame, now_s);
        ++summary.commands_sent;
        if (target_exposure_t_s) {
          latency_ms.push(1e3 * (now_s - *target_exposure_t_s));
          overhead_ms.push(1e3 * (now_s - target_publish_t_s));
          target_exposure_t_s.reset();
        }
      }
    } else {
      ++summary.commands_withheld;
    }
    diagnose(now_s, out);
    tick_ms.push(wall_ms_since(t0));
  }
};

OnboardLoop::OnboardLoop(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OnboardLoop::~OnboardLoop() {
  if (impl_ && impl_->diagnostics) std::fclose(impl_->diagnostics);
}

std::expected<std::unique_ptr<OnboardLoop>, std::string> OnboardLoop::create(const vision::CadModel& model,
                                                                              const vision::Camera& camera,
                                                                              const OnboardOptions& options,
                                                                              const OnboardPorts& ports) {
  if (!ports.clock || !ports.bus || !ports.camera || !ports.wait_until)
    return std::unexpected("onboard loop: clock, bus, camera and wait_until are all needed");
  if (!(options.control_rate_hz > 0) || !(options.time_sync_period_s > 0) || !(options.diagnostics_period_s > 0))
    return std::unexpected("onboard loop: control_rate_hz, time_sync_period_s and diagnostics_period_s must be > 0");
  fusion::PredictorOptions p = options.predictor;
  p.imu_time_offset_s = 0;  // samples arrive on the controller clock (time sync)
  auto predictor = fusion::Predictor::create(p);
  if (!predictor) return std::unexpected("onboard loop: predictor: " + predictor.error());
  auto controller = HeadController::create(options.controller);
  if (!controller) return std::unexpected("onboard loop: head controller: " + controller.error());
  controller->request(options.mode);
  auto impl = std::make_unique<Impl>(model, camera, options, ports, std::move(*predictor), std::move(*controller));
  if (!options.candump_path.empty()) {
    auto log = fw::CandumpWriter::open(options.candump_path);
    if (!log) return std::unexpected("onboard loop: " + log.error());
    impl->log.emplace(std::move(*log));
  }
  if (!options.diagnostics_path.empty()) {
    impl->diagnostics = std::fopen(options.diagnostics_path.c_str(), "w");
    if (!impl->diagnostics) return std::unexpected("onboard loop: cannot write " + options.diagnostics_path);
  }
  return std::unique_ptr<OnboardLoop>(new OnboardLoop(std::move(impl)));
}

void OnboardLoop::set_initial_pose(double t_s, const Eigen::Isometry3d& cam_T_obj) {
  impl_->last_good = cam_T_obj;
  impl_->init_t_s = t_s;
  impl_->init_pending = true;
}

std::expected<OnboardSummary, std::string> OnboardLoop::run(double until_s, const FrameHook& hook) {
  Impl& s = *impl_;
  if (auto ok = s.ports.camera->start(); !ok) return std::unexpected("camera: " + ok.error());
  const double period = 1.0 / s.options.control_rate_hz;
  double next = s.ports.clock->now_s();
  while (next <= until_s) {
    if (auto ok = s.ports.wait_until(next); !ok) return std::unexpected(ok.error());
    const double now = s.ports.clock->now_s();
    if (now - next > period) ++s.summary.late_ticks;
    s.tick(now, hook);
    ++s.summary.ticks;
    next += period;
    if (next < now) next = now;  // a late loop does not try to catch up tick by tick
  }
  s.ports.camera->stop();
  if (s.log) {
    if (auto ok = s.log->close(); !ok) return std::unexpected(ok.error());
  }
  if (s.diagnostics) std::fflush(s.diagnostics);
  OnboardSummary out = s.summary;
  out.track_ms_median = s.track_ms.percentile(0.5);
  out.track_ms_p99 = s.track_ms.percentile(0.99);
  out.tick_ms_median = s.tick_ms.percentile(0.5);
  out.tick_ms_p99 = s.tick_ms.percentile(0.99);
  out.exposure_to_command_ms_median = s.latency_ms.percentile(0.5);
  out.exposure_to_command_ms_max = s.latency_ms.max();
  out.frame_age_at_take_ms_median = s.frame_age_ms.percentile(0.5);
  out.result_to_command_ms_max = s.overhead_ms.max();
  out.controller = s.controller.counters();
  out.imu_assembly = s.assembler.counters();
  out.predictor = s.predictor.status(s.ports.clock->now_s()).counters;
  return out;
}

}  // namespace epichead::head
