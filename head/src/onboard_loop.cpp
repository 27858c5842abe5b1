#include "epichead/head/onboard_loop.h"


#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <thread>
#include <variant>

#include <nlohmann/json.hpp>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/protocol.h"
#include "epichead/fusion/carried_orientation.h"
#include "epichead/head/target_observation.h"
#include "epichead/vision/constant_velocity.h"
#include "epichead/vision/model_centre.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/revolution_axis.h"
#include "realtime.h"
#include "recent_samples.h"
#include "recorder.h"
#include "vision_stage.h"

namespace epichead::head {
namespace {

namespace fw = firmware_iface;
using WallClock = std::chrono::steady_clock;

// The bus is read once per control tick.
ClockSyncOptions clock_sync_options(const OnboardOptions& o) {
  ClockSyncOptions c = o.imu_clock_sync;
  c.read_resolution_s = 1.0 / o.control_rate_hz;
  return c;
}

double wall_ms_since(WallClock::time_point t0) {
  return std::chrono::duration<double, std::milli>(WallClock::now() - t0).count();
}

}  // namespace

struct OnboardLoop::Impl {
  Impl(const vision::CadModel& m, const vision::Camera& cam, const OnboardOptions& o, const OnboardPorts& p,
       fusion::Predictor pred, HeadController ctrl, std::unique_ptr<Recorder> rec)
      : model(&m), camera(cam), options(o), ports(p),
        vision(m, cam, o.tracker, o.threads, o.processing_s, *p.clock), predictor(std::move(pred)),
        arbiter(o.predictor.gate_chi2),
        controller(std::move(ctrl)), target_point_obj(vision::model_centre(m)), imu_clock(clock_sync_options(o)),
        recorder(std::move(rec)), carried(o.predictor.mount.cam_R_imu, fusion::CarriedOrientationNoise{}) {}

  const vision::CadModel* model;
  vision::Camera camera;
  OnboardOptions options;
  OnboardPorts ports;
  VisionStage vision;
  fusion::Predictor predictor;
  fusion::VisionArbiter arbiter;  // who is wrong when vision and the predictor disagree
  HeadController controller;
  Eigen::Vector3d target_point_obj;
  DeviceClockSync imu_clock;
  ImuFrameAssembler assembler;
  std::unique_ptr<Recorder> recorder;
  std::atomic<bool> stop_requested{false};
  // The object's orientation the gyro carries from the filter's last applied pose (or the start
  // pose given): detection after a loss looks for the object turned so (as `track` does).
  fusion::CarriedOrientation carried;
  bool init_given = false;  // the pending start pose is the user's (set_initial_pose), not a detection's

  // Initial pose and the last good one: where windows go while the predictor has nothing.
  Eigen::Isometry3d last_good = Eigen::Isometry3d::Identity();
  // The vision poses extrapolated alone: the tracker's second opinion when the predictor's pose
  // finds nothing usable (the filter has left the object), as in `track`; the arbiter then
  // restarts the filter from a pose so found that the image supports well.
  vision::ConstantVelocity vision_only{0.0, Eigen::Isometry3d::Identity()};
  double init_t_s = 0;
  bool init_pending = false;
  bool have_pose = false;  // a start pose was given or detected
  std::unique_ptr<vision::Detector> detector;
  int lost_run = 0;        // lost results in a row

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
  RecentSamples lateness_us{1 << 18}, vision_latency_ms{1 << 14};
  double lateness_us_max = 0, tick_work_us_max = 0, vision_latency_ms_max = 0;  // over the whole run
  std::uint64_t frame_index = 0;
  double camera_read_ms = 0;  // wall time of this tick's next_frame() (the simulator renders in it)
  double hook_ms = 0;         // wall time of this tick's calls of the caller's frame hook
  double next_sync_s = 0, next_diag_s = 0;
  std::uint64_t heartbeats = 0;

  void record(const fw::StampedCanFrame& f, fw::CanDirection dir) { recorder->frame(f, dir); }
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
    if (v == fusion::ImuVerdict::Accepted || v == fusion::ImuVerdict::Buffered) carried.add_gyro(s.t_s, s.gyro_radps);
  }

  // The filter's orientation at t_s (just updated) is what the gyro carries from here.
  void carry(double t_s) { carried.set_from(predictor, t_s); }

  // A new camera frame, if one is ready: to the vision stage with the pose predicted at its
  // exposure, or dropped (counted) while the stage is busy with an earlier one.
  // Returns whether a job was submitted.
  bool take_frame(double now_s) {
    hw::CameraFrame frame;
    const auto t0 = WallClock::now();
    const hw::CameraRead r = ports.camera->next_frame(frame, 0);
    camera_read_ms = wall_ms_since(t0);
    if (r == hw::CameraRead::Lost) ++summary.camera_lost;
    if (r != hw::CameraRead::Frame) return false;
    if (vision.busy()) {
      ++summary.frames_dropped_vision_busy;
      return false;
    }
    // A frame cannot have been exposed after it arrived: a stamp ahead of the loop's clock (a
    // driver that stamps the frame's scheduled time, as vivid does under load) is taken as now.
    double exposure = frame.t_s;
    if (exposure > now_s) {
      ++summary.frames_stamped_ahead;
      exposure = now_s;
    }
    if (init_pending) {
      const auto v = predictor.add_vision(init_t_s, last_good, vision::initial_pose_covariance()).verdict;
      init_pending = v != fusion::VisionVerdict::Initialised && v != fusion::VisionVerdict::Applied;
      if (!init_pending && init_given) carry(init_t_s);
    }
    VisionJob& job = vision.prepare(frame);
    const auto prediction = predictor.predict(exposure);
    job.index = frame_index++;
    job.exposure_t_s = exposure;
    job.taken_t_s = now_s;
    job.predicted = prediction ? prediction->cam_T_obj : last_good;
    job.fallback.reset();
    if (prediction && have_pose) job.fallback = vision_only.predict(exposure);
    // No start yet, or lost for a few frames: the stage looks for the object instead.
    job.detect = detector && (!have_pose || lost_run >= options.lost_frames_before_detection);
    job.detect_near = job.orient_like_predicted = job.detect && have_pose;
    job.up_cam.reset();
    job.up_obj.reset();
    job.carried_cam_R_obj.reset();
    if (job.detect && have_pose) {
      if (const auto c = carried.at(exposure)) {
        job.carried_cam_R_obj = c->cam_R_obj;
        job.turn_tolerance_deg = fusion::carried_turn_tolerance_deg(*c);
      }
    }
    if (job.detect) {
      // With the down learnt while tracking, the search keeps only poses upright as the object
      // stands, and a prediction that itself tilts the object away (after an IMU gap) is no place
      // to look near.
      const auto down_cam = predictor.measured_down_cam(exposure);
      const auto down_obj = predictor.learnt_down_obj();
      if (down_cam && down_obj) {
        job.up_cam = -*down_cam;
        job.up_obj = -*down_obj;
        if (prediction && predictor.tilt_error_rad(exposure, prediction->cam_T_obj) > options.predictor.gravity_check.max_tilt_error_rad)
          job.detect_near = false;
      }
    }
    frame_age_ms.push(1e3 * (now_s - exposure));
    vision.submit(now_s);
    return true;
  }

  // The vision stage's result once it is published: the predictor's late update and the
  // controller's target.
  void publish(double now_s, const FrameHook& hook) {
    const VisionResult* r = vision.poll(now_s);
    if (!r) return;
    if (!r->readable) {
      ++summary.unreadable_frames;
      vision.release();
      return;
    }
    const vision::FrameReport& report = *r->report;
    if (!r->detection) track_ms.push(r->track_ms);  // a detection is timed apart (detect_ms_max)
    ++summary.frames;
    // A pose that tilts the object away from the down the accelerometer measures is a wrong lock
    // (a printed edge, clutter), however well the image supports it: the frame counts as lost,
    // so that detection runs after a few, and neither the predictor nor the controller takes it.
    vision::TrackStatus status = report.status;
    const bool against_gravity = status != vision::TrackStatus::Lost && predictor.check_tilt(r->exposure_t_s, report.cam_T_obj);
    if (against_gravity) {
      status = vision::TrackStatus::Lost;
      ++summary.against_gravity;
    }
    (status == vision::TrackStatus::Lost ? summary.lost : summary.tracked) += 1;
    summary.fallback_frames += !r->detection && report.used_fallback;
    // Inline: at the modelled time the stage set; Thread: now, when the control thread takes it.
    const double published = options.threads == VisionThreads::Inline ? r->done_t_s : now_s;
    const double latency_ms = 1e3 * (published - r->exposure_t_s);
    vision_latency_ms.push(latency_ms);
    vision_latency_ms_max = std::max(vision_latency_ms_max, latency_ms);
    if (hook) {
      const auto h0 = WallClock::now();
      hook({summary.frames - 1, r->exposure_t_s, published, r->predicted, &report, r->tracker, r->image, status, against_gravity});
      hook_ms += wall_ms_since(h0);
    }
    last_status = status;
    count_acquisition(*r, status, against_gravity);
    if (r->detection && r->found && status != vision::TrackStatus::Lost) {
      // Found by detection: the predictor starts again from this pose, as from a start pose.
      predictor.reset();
      arbiter.clear();
      last_good = report.cam_T_obj;
      vision_only.restart(r->exposure_t_s, report.cam_T_obj);
      init_t_s = r->exposure_t_s;
      init_pending = true;
      init_given = false;
      have_pose = true;
      target = target_from_pose(r->exposure_t_s, report.cam_T_obj, target_point_obj);
      target_exposure_t_s = r->exposure_t_s;
      target_publish_t_s = published;
      vision.release();
      return;
    }
    if (!r->detection) vision_only.observe(r->exposure_t_s, status, report.cam_T_obj);
    if (status != vision::TrackStatus::Lost) {  // else the controller's watchdog sees the target go stale
      last_good = report.cam_T_obj;
      // Vision and the filter disagree: the arbiter decides which is wrong, as `track` does.
      const fusion::VisionVerdict v = arbiter.add_vision(predictor, r->exposure_t_s, report.cam_T_obj, report.covariance,
                                                         {vision::strongly_supported(report), report.used_fallback})
                                          .final()
                                          .verdict;
      // Before, the start pose was offered again with every frame and refused each time
      // (vision_rejected counted every frame of every sim-run).
      if (fusion::supersedes_start_pose(v)) init_pending = false;
      if (v == fusion::VisionVerdict::Applied || v == fusion::VisionVerdict::Initialised) carry(r->exposure_t_s);
      target = target_from_pose(r->exposure_t_s, report.cam_T_obj, target_point_obj);
      target_exposure_t_s = r->exposure_t_s;
      target_publish_t_s = published;
    }
    vision.release();
  }

  void count_acquisition(const VisionResult& r, vision::TrackStatus status, bool against_gravity) {
    if (r.detection) {
      ++summary.detections;
      summary.found_turned_away_from_carried += r.turned_away;
      summary.detect_ms_max = std::max(summary.detect_ms_max, r.track_ms);
      if (r.found && !against_gravity) {
        ++summary.detections_found;
        summary.levelled_to_gravity += r.levelled;
        if (have_pose) ++summary.reacquisitions;
        if (summary.first_detection_t_s < 0) summary.first_detection_t_s = r.exposure_t_s;
      }
    }
    if (status == vision::TrackStatus::Lost) {
      if (lost_run == 0 && have_pose) ++summary.losses;
      ++lost_run;
    } else {
      lost_run = 0;
    }
  }

  void diagnose(double now_s, const ControlOutput& out) {
    if (options.diagnostics_path.empty()) return;
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
      recorder->line(j.dump());
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
                           {"predictor", {{"vision_applied", st.counters.vision_applied},
                                          {"vision_gated", st.counters.vision_gated},
                                          {"vision_rejected", st.counters.vision_too_old + st.counters.vision_out_of_order +
                                                                  st.counters.vision_bad_input + st.counters.vision_no_imu},
                                          {"reinitialisations", st.counters.reinitialisations},
                                          {"restarts_from_vision", arbiter.counters().fallback + arbiter.counters().supported_gated +
                                                                       arbiter.counters().agreeing_gated},
                                          {"imu_restarts", st.counters.imu_restarts},
                                          {"last_nis", st.last_nis}}},
                           {"commands_sent", summary.commands_sent},
                           {"bus_state", hw::to_string(bus_state)},
                           {"target_error_deg", std::isfinite(out.target_error_rad) ? out.target_error_rad * 180 / M_PI : -1.0},
                           {"clock_round_trip_ms", imu_clock.round_trip_s() * 1e3},
                           {"frames_dropped_vision_busy", summary.frames_dropped_vision_busy},
                           {"late_ticks", summary.late_ticks},
                           {"tick_lateness_us_max", lateness_us_max}};
    recorder->line(j.dump());
  }

  void tick(double now_s, const FrameHook& hook) {
    const auto t0 = WallClock::now();
    hook_ms = 0;
    // On a grid of time_sync_period_s, with half a tick of slack: a clock that reads a hair before
    // the due tick (rounding, the simulator's integer clock) would otherwise send one tick late,
    // every time (101 ms instead of 100). After a stall the grid starts again from now.
    if (now_s >= next_sync_s - 0.5 / options.control_rate_hz) {
      next_sync_s += options.time_sync_period_s;
      if (next_sync_s <= now_s) next_sync_s = now_s + options.time_sync_period_s;
      if (auto frame = fw::encode(imu_clock.make_request(now_s))) send(frame->frame, now_s);
    }
    drain_bus(now_s);
    publish(now_s, hook);
    const bool submitted = take_frame(now_s);
    const double inline_vision_ms = submitted && options.threads == VisionThreads::Inline ? vision.inline_wall_ms() : 0;
    publish(now_s, hook);  // Inline with processing_s == 0 publishes at once
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
    // The tick's own work: inline tracking is the vision stage's time, not the control loop's;
    // the simulator's camera renders the frame inside next_frame(), which is the simulator's time
    // too. On the robot a camera read is a dequeue and counts. The caller's frame hook (sim-run's
    // comparison with the truth and its overlay PNGs, 15-20 ms a frame written) is the caller's:
    // `run` gives none.
    const double simulator_ms = ports.simulated ? camera_read_ms : 0;
    const double work_ms = std::max(0.0, wall_ms_since(t0) - inline_vision_ms - simulator_ms - hook_ms);
    tick_ms.push(work_ms);
    tick_work_us_max = std::max(tick_work_us_max, 1e3 * work_ms);
  }
};

OnboardLoop::OnboardLoop(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
OnboardLoop::~OnboardLoop() = default;

std::expected<std::unique_ptr<OnboardLoop>, std::string> OnboardLoop::create(const vision::CadModel& model,
                                                                              const vision::Camera& camera,
                                                                              const OnboardOptions& options,
                                                                              const OnboardPorts& ports) {
  if (!ports.clock || !ports.bus || !ports.camera || !ports.wait_until)
    return std::unexpected("onboard loop: clock, bus, camera and wait_until are all needed");
  if (const double rt = options.imu_clock_sync.max_round_trip_s; !(rt > 0 && rt <= kMaxClockSyncRoundTrip_s))
    return std::unexpected("onboard loop: imu_clock_sync.max_round_trip_s must be in (0, " +
                           std::to_string(kMaxClockSyncRoundTrip_s) + "] s, got " + std::to_string(rt));
  if (!(options.control_rate_hz > 0) || !(options.time_sync_period_s > 0) || !(options.diagnostics_period_s > 0))
    return std::unexpected("onboard loop: control_rate_hz, time_sync_period_s and diagnostics_period_s must be > 0");
  fusion::PredictorOptions p = options.predictor;
  p.imu_time_offset_s = 0;  // samples arrive on the controller clock (time sync)
  // A body of revolution's poses turn freely about its axis: only the axis's tilt is checked.
  if (const auto axis = vision::find_revolution_axis(model)) p.gravity_check.free_turn_axis_obj = axis->direction_obj.normalized();
  auto predictor = fusion::Predictor::create(p);
  if (!predictor) return std::unexpected("onboard loop: predictor: " + predictor.error());
  auto controller = HeadController::create(options.controller);
  if (!controller) return std::unexpected("onboard loop: head controller: " + controller.error());
  controller->request(options.mode);
  if (const char* why = fw::candump_iface_problem(options.candump_iface))
    return std::unexpected("onboard loop: CAN interface name '" + options.candump_iface + "' cannot be recorded: it " + why);
  Recorder::ClockPairSource log_clocks = hw::read_clock_pair;
  if (ports.simulated) log_clocks = [epoch_us = options.simulated_log_epoch_unix_us] { return hw::ClockPair{0, epoch_us}; };
  auto recorder = Recorder::open(options.candump_path, options.candump_iface, options.diagnostics_path,
                                 options.threads == VisionThreads::Thread ? Recorder::Mode::Thread : Recorder::Mode::Inline,
                                 std::move(log_clocks));
  if (!recorder) return std::unexpected("onboard loop: " + recorder.error());
  auto impl = std::make_unique<Impl>(model, camera, options, ports, std::move(*predictor), std::move(*controller),
                                     std::move(*recorder));
  return std::unique_ptr<OnboardLoop>(new OnboardLoop(std::move(impl)));
}

void OnboardLoop::request_stop() { impl_->stop_requested.store(true, std::memory_order_relaxed); }

void OnboardLoop::set_initial_pose(double t_s, const Eigen::Isometry3d& cam_T_obj) {
  impl_->last_good = cam_T_obj;
  impl_->vision_only.restart(t_s, cam_T_obj);
  impl_->init_t_s = t_s;
  impl_->init_pending = true;
  impl_->init_given = true;
  impl_->have_pose = true;
}

void OnboardLoop::set_detector(std::unique_ptr<vision::Detector> detector) {
  impl_->detector = std::move(detector);
  impl_->vision.set_detector(impl_->detector.get(), impl_->options.detection_processing_s);
}

std::expected<OnboardSummary, std::string> OnboardLoop::run(double until_s, const FrameHook& hook) {
  Impl& s = *impl_;
  if (auto ok = s.ports.camera->start(); !ok) return std::unexpected("camera: " + ok.error());
  const RealtimeOptions& rt = s.options.realtime;
  if (s.options.threads == VisionThreads::Thread) {
    const std::string memory = rt.lock_memory ? lock_memory() + "; " : "";
    s.summary.threads = memory + "control: " + pin_current_thread(rt.control_cpu) + ", " + request_fifo(rt.control_priority);
    std::atomic<bool> vision_ready{false};
    std::string vision_note;
    s.vision.start([&] {
      vision_note = "; vision: " + pin_current_thread(rt.vision_cpu) + ", " + request_fifo(rt.vision_priority);
      vision_ready.store(true, std::memory_order_release);
    });
    while (!vision_ready.load(std::memory_order_acquire)) std::this_thread::yield();
    s.summary.threads += vision_note;
  } else {
    s.summary.threads = "inline: vision and recording on the control thread (simulated time)";
  }
  const double period = 1.0 / s.options.control_rate_hz;
  double next = s.ports.clock->now_s();
  std::expected<void, std::string> failed;
  while (next <= until_s && !s.stop_requested.load(std::memory_order_relaxed)) {
    if (auto ok = s.ports.wait_until(next); !ok) {
      failed = std::unexpected(ok.error());
      break;
    }
    const double now = s.ports.clock->now_s();
    const double late_us = std::max(0.0, 1e6 * (now - next));
    s.lateness_us.push(late_us);
    s.lateness_us_max = std::max(s.lateness_us_max, late_us);
    if (now - next > period) ++s.summary.late_ticks;
    s.tick(now, hook);
    ++s.summary.ticks;
    next += period;
    if (next < now) next = now;  // a late loop does not try to catch up tick by tick
  }
  s.vision.stop();
  s.ports.camera->stop();
  const RecorderCounters rc = s.recorder->counters();
  auto closed = s.recorder->close();
  if (!failed) return std::unexpected(failed.error());
  if (!closed) return std::unexpected(closed.error());
  OnboardSummary out = s.summary;
  out.frames_logged = rc.frames_logged;
  out.log_frames_dropped = rc.frames_dropped;
  out.log_lines_dropped = rc.lines_dropped;
  out.log_write_errors = rc.write_errors;
  out.log_frame_queue_high_water = rc.frame_queue_high_water;
  out.log_line_queue_high_water = rc.line_queue_high_water;
  out.track_ms_median = s.track_ms.percentile(0.5);
  out.track_ms_p99 = s.track_ms.percentile(0.99);
  out.tick_ms_median = s.tick_ms.percentile(0.5);
  out.tick_ms_p99 = s.tick_ms.percentile(0.99);
  out.tick_work_us_median = 1e3 * out.tick_ms_median;
  out.tick_work_us_p99 = 1e3 * out.tick_ms_p99;
  out.tick_work_us_max = s.tick_work_us_max;
  out.tick_lateness_us_median = s.lateness_us.percentile(0.5);
  out.tick_lateness_us_p99 = s.lateness_us.percentile(0.99);
  out.tick_lateness_us_max = s.lateness_us_max;
  out.vision_latency_ms_median = s.vision_latency_ms.percentile(0.5);
  out.vision_latency_ms_p99 = s.vision_latency_ms.percentile(0.99);
  out.vision_latency_ms_max = s.vision_latency_ms_max;
  out.exposure_to_command_ms_median = s.latency_ms.percentile(0.5);
  out.exposure_to_command_ms_max = s.latency_ms.max();
  out.frame_age_at_take_ms_median = s.frame_age_ms.percentile(0.5);
  out.result_to_command_ms_max = s.overhead_ms.max();
  out.controller = s.controller.counters();
  out.backlash_band = s.controller.backlash_band();
  out.imu_assembly = s.assembler.counters();
  out.imu_clock = s.imu_clock.counters();
  out.predictor = s.predictor.status(s.ports.clock->now_s()).counters;
  out.predictor_restarts = s.arbiter.counters();
  return out;
}

}  // namespace epichead::head
