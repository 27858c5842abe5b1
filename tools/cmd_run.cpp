// `epichead run --config FILE [--seconds S]`: the onboard loop on real devices: a V4L2 camera, a
// SocketCAN bus carrying the IMU and the head, the monotonic clock. The configuration's keys are
// described in run_config.h. Writes OUT/bus.log (candump, stamped on the wall clock like candump's
// so that the two merge), OUT/diagnostics.jsonl (the monotonic clock; its first line, clock_map,
// maps one onto the other) and OUT/summary.json.
#include <CLI/CLI.hpp>

#include <time.h>

#include <cmath>
#include <cstdio>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include "command.h"
#include "detection_setup.h"
#include "stop_signals.h"
#include "onboard_summary_json.h"
#include "run_config.h"
#include "epichead/head/onboard_loop.h"
#include "epichead/hw/clock.h"
#include "epichead/hw/monotonic_stamped_bus.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/hw/v4l2_camera.h"
#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/offline/stamped_pose.h"

namespace epichead::tools {
namespace {

namespace fs = std::filesystem;

// Ctrl-C or SIGTERM ends the run after the current tick, so the logs and the summary are written.
std::atomic<head::OnboardLoop*> running_loop{nullptr};
extern "C" void on_run_stop_signal(int) {
  if (head::OnboardLoop* loop = running_loop.load()) loop->request_stop();
}

int run_onboard(const std::string& config_path, double seconds) {
  const char* cmd = "run";
  auto config = read_run_config(config_path);
  if (!config) return fail(cmd, config.error());
  static const std::map<std::string, head::ControlMode> modes{
      {"fixate", head::ControlMode::Fixate}, {"stabilise", head::ControlMode::Stabilise}, {"hold", head::ControlMode::Hold}};
  const auto mode = modes.find(config->mode);
  if (mode == modes.end()) return fail(cmd, config_path + ": mode must be fixate, stabilise or hold");
  auto model = vision::load_cao(config->model);
  if (!model) return fail(cmd, model.error());
  auto camera_model = vision::Camera::load(config->calibration);
  if (!camera_model) return fail(cmd, camera_model.error());
  std::optional<Eigen::Isometry3d> init_pose;
  if (!config->init_pose.empty()) {
    auto init = vision::read_pose_csv(config->init_pose);
    if (!init) return fail(cmd, init.error());
    if (init->empty()) return fail(cmd, config->init_pose + ": no pose");
    init_pose = init->front().cam_T_obj;
  }
  std::error_code ec;
  fs::create_directories(config->out, ec);
  if (ec) return fail(cmd, "cannot create " + config->out + ": " + ec.message());

  auto bus = hw::SocketCanBus::open(config->can);
  if (!bus) return fail(cmd, bus.error());
  auto camera = hw::V4l2Camera::open(config->camera);
  if (!camera) return fail(cmd, camera.error());
  // The driver may choose another size than the one asked for: it must be the calibration's.
  if ((*camera)->format().width != camera_model->width_px() || (*camera)->format().height != camera_model->height_px())
    return fail(cmd, config->camera.device + " gives " + std::to_string((*camera)->format().width) + "x" +
                         std::to_string((*camera)->format().height) + " frames but " + config->calibration +
                         " is a calibration for " + std::to_string(camera_model->width_px()) + "x" +
                         std::to_string(camera_model->height_px()));
  hw::MonotonicClock clock;
  head::OnboardPorts ports;
  ports.clock = &clock;
  // SocketCAN stamps with the wall clock, the loop runs on the monotonic one (monotonic_stamped_bus.h);
  // the recorder's writer maps the loop's stamps back onto the wall clock for bus.log, as candump
  // stamps (head/log_clock.h: one clock pair, steps of the wall clock followed forward only).
  hw::MonotonicStampedBus monotonic_bus(**bus);
  ports.bus = &monotonic_bus;
  ports.camera = camera->get();
  ports.wait_until = [&clock](double t_s) -> std::expected<void, std::string> {
    // Absolute sleep on the monotonic clock: a late wake-up does not shift later ticks.
    const double wait = t_s - clock.now_s();
    if (wait <= 0) return {};
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    const double target = static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec) + wait;
    ts.tv_sec = static_cast<time_t>(target);
    ts.tv_nsec = static_cast<long>((target - std::floor(target)) * 1e9);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
    }
    return {};
  };
  head::OnboardOptions options;
  options.mode = mode->second;
  options.controller = controller_options(*config, options.controller);  // gains and backlash from the file
  options.candump_path = (fs::path(config->out) / "bus.log").string();
  options.candump_iface = config->can.interface;
  options.diagnostics_path = (fs::path(config->out) / "diagnostics.jsonl").string();
  // Vision and recording on threads of their own: the control loop never waits for them.
  options.threads = head::VisionThreads::Thread;
  options.imu_clock_sync.max_round_trip_s = config->time_sync_max_round_trip_s;
  options.realtime = config->threads;
  // The object's up when told: poses are checked against gravity from the start, and detection
  // searches only upright views.
  if (config->object_up) options.predictor.gravity_check.told_down_obj = -*config->object_up;
  auto loop = head::OnboardLoop::create(*model, *camera_model, options, ports);
  if (!loop) return fail(cmd, loop.error());
  // Detection: the start when no init_pose is given, and after every loss. Templates are read
  // from the cache (or built, with progress) before the loop starts: never on its clock.
  if (!init_pose || config->reacquire) {
    DetectionArgs detection;
    if (!config->template_cache.empty()) detection.cache_dir = config->template_cache;
    auto detector = make_detector(cmd, *model, *camera_model, detection, options.tracker);
    if (!detector) return fail(cmd, detector.error());
    (*loop)->set_detector(std::move(*detector));
  }
  if (init_pose) (*loop)->set_initial_pose(clock.now_s(), *init_pose);
  else std::printf("run: no init_pose: the object is detected from the model\n");
  const double until = seconds > 0 ? clock.now_s() + seconds : std::numeric_limits<double>::infinity();
  running_loop.store(loop->get());
  on_stop_signals(on_run_stop_signal);
  auto summary = (*loop)->run(until);
  running_loop.store(nullptr);
  if (!summary) return fail(cmd, summary.error());
  const std::string summary_path = (fs::path(config->out) / "summary.json").string();
  std::ofstream summary_file(summary_path);
  summary_file << summary_json(*summary).dump(1) << '\n';
  if (!summary_file.flush()) return fail(cmd, "cannot write " + summary_path);
  std::printf("run: %llu ticks (%llu late), %llu frames (%llu tracked, %llu lost), %llu IMU samples, %llu commands\n",
              static_cast<unsigned long long>(summary->ticks), static_cast<unsigned long long>(summary->late_ticks),
              static_cast<unsigned long long>(summary->frames), static_cast<unsigned long long>(summary->tracked),
              static_cast<unsigned long long>(summary->lost), static_cast<unsigned long long>(summary->imu_samples),
              static_cast<unsigned long long>(summary->commands_sent));
  if (summary->imu_samples == 0) {
    const head::ClockSyncCounters& sync = summary->imu_clock;
    std::printf("run: warning: no IMU samples: %s (%llu time-sync requests, %llu replies used, %llu refused for a "
                "round trip over %.0f ms or no matching request)\n",
                sync.replies == 0 ? "the IMU's clock was never synchronised" : "no gyro/accelerometer pair was accepted (summary.json: imu_assembly, imu_rejected)",
                static_cast<unsigned long long>(sync.requests), static_cast<unsigned long long>(sync.replies),
                static_cast<unsigned long long>(sync.rejected), options.imu_clock_sync.max_round_trip_s * 1e3);
  }
  const hw::CanBusStats bus_stats = (*bus)->stats();
  std::printf("run: tracking %.1f ms median, tick work %.2f ms median; bus: %llu frames received, %llu dropped by the "
              "kernel (receive queue full), %llu sends failed; camera: %llu frames dropped by the device, %llu stamped "
              "ahead of the loop's clock\n",
              summary->track_ms_median, summary->tick_ms_median, static_cast<unsigned long long>(bus_stats.rx_frames),
              static_cast<unsigned long long>(bus_stats.rx_dropped), static_cast<unsigned long long>(bus_stats.tx_failed),
              static_cast<unsigned long long>((*camera)->stats().dropped_frames),
              static_cast<unsigned long long>(summary->frames_stamped_ahead));
  std::printf("run: control ticks late %.0f us median, %.0f us p99, %.0f us max; %llu of %llu ticks missed (%.3f %%); "
              "vision latency %.1f ms median, %.1f ms p99; %llu frames dropped while vision was busy; %llu log records "
              "dropped\n",
              summary->tick_lateness_us_median, summary->tick_lateness_us_p99, summary->tick_lateness_us_max,
              static_cast<unsigned long long>(summary->late_ticks), static_cast<unsigned long long>(summary->ticks),
              summary->ticks ? 100.0 * static_cast<double>(summary->late_ticks) / static_cast<double>(summary->ticks) : 0.0,
              summary->vision_latency_ms_median, summary->vision_latency_ms_p99,
              static_cast<unsigned long long>(summary->frames_dropped_vision_busy),
              static_cast<unsigned long long>(summary->log_frames_dropped + summary->log_lines_dropped));
  std::printf("run: threads: %s\n", summary->threads.c_str());
  std::printf("run: wrote %s, %s and %s\n", options.candump_path.c_str(), options.diagnostics_path.c_str(),
              summary_path.c_str());
  return 0;
}

const CommandRegistration registration{
    "run", "The onboard loop on real devices (V4L2 camera, SocketCAN IMU and head)", [](CLI::App& app) {
      auto config = std::make_shared<std::string>();
      auto seconds = std::make_shared<double>(0);
      app.add_option("--config", *config, "JSON configuration (keys below)")->required();
      app.footer(run_config_help(head::HeadControllerOptions{}));
      app.add_option("--seconds", *seconds, "Stop after this long (default: run until interrupted)")->check(CLI::Range(0.0, 1e9));
      return [=]() { return run_onboard(*config, *seconds); };
    }};

}  // namespace
}  // namespace epichead::tools
