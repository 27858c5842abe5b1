#pragma once
// The onboard program's loop: camera frames, IMU samples and head state come in through the hw
// ports, head commands go out through them. Per 1 ms tick: drain the bus (IMU pairs -> the
// Kalman predictor, head state, time-sync replies, heartbeats), take a new camera frame if one is
// ready (predicted pose at its exposure time -> tracker -> vision update -> target for fixation),
// step the head controller and send its command, send a time-sync request every
// time_sync_period_s. Everything received and sent is recorded in a candump log; a JSON line per
// diagnostics period (and per controller event) goes to the diagnostics stream.
//
// The same code runs on the robot (Linux drivers, wall-clock waits) and in the closed-loop
// simulator (simulated ports, waits that advance simulated time), in two stages: the control
// thread above, and the vision stage, which tracks one frame at a time and hands its result
// back without the control thread ever waiting for it (head/src/vision_stage.h). On the robot
// (VisionThreads::Thread) vision and recording run on threads of their own; in the simulator
// (VisionThreads::Inline) the control thread tracks the frame when it takes it and publishes the
// result `processing_s` later in simulated time, so that the same seed gives the same run.
#include <cstdint>
#include <cstdio>
#include <expected>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "epichead/firmware_iface/candump_writer.h"
#include "epichead/fusion/predictor.h"
#include "epichead/fusion/vision_arbiter.h"
#include "epichead/head/device_clock_sync.h"
#include "epichead/head/head_controller.h"
#include "epichead/head/imu_frame_assembler.h"
#include "epichead/head/log_clock.h"
#include "epichead/head/realtime_options.h"
#include "epichead/hw/camera_port.h"
#include "epichead/hw/can_bus.h"
#include "epichead/hw/clock.h"
#include "epichead/vision/detector.h"
#include "epichead/vision/model_tracker.h"

namespace epichead::head {

struct OnboardPorts {
  hw::Clock* clock = nullptr;
  hw::CanBus* bus = nullptr;
  hw::CameraPort* camera = nullptr;
  // Blocks (robot) or advances simulated time (simulator) until the clock reads t_s.
  std::function<std::expected<void, std::string>(double t_s)> wait_until;
  // The simulator's ports: its camera renders the frame inside next_frame(), which the tick's
  // work figure (OnboardSummary::tick_work_us_*) then leaves out, as the simulator's time; its
  // candump log starts at OnboardOptions::simulated_log_epoch_unix_us instead of the wall clock.
  bool simulated = false;
};

// How the vision stage and the recorder run: Inline (deterministic, the simulator) or on threads of
// their own (the robot; `sim-run --threads wall`).
enum class VisionThreads { Inline, Thread };

struct OnboardOptions {
  double control_rate_hz = 1000;
  double time_sync_period_s = 0.1;
  // Which time-sync replies are precise enough to map the IMU's clock. Its read_resolution_s is
  // the loop's own (one control period: the bus is read once a tick) and is set by the loop.
  ClockSyncOptions imu_clock_sync;
  double diagnostics_period_s = 0.1;
  VisionThreads threads = VisionThreads::Inline;
  RealtimeOptions realtime;
  double processing_s = -1;            // Inline, >= 0: vision results are published this long after the frame arrived
  ControlMode mode = ControlMode::Fixate;
  vision::ModelTrackerOptions tracker;
  fusion::PredictorOptions predictor;  // the IMU is mapped to the controller clock here: its offset is unused
  HeadControllerOptions controller;
  std::string candump_path;            // empty: no recording
  std::string candump_iface = "can0";
  // The candump log is stamped on the Unix epoch, as candump stamps (head/log_clock.h). On the
  // robot the loop's clock (CLOCK_MONOTONIC) is mapped through the system's wall clock; with
  // simulated ports, simulated time 0 is written as this fixed date, so the same seed writes the
  // same log (sim-run --log-epoch).
  std::int64_t simulated_log_epoch_unix_us = kSimulatedLogEpochUnix_us;
  std::string diagnostics_path;        // JSON lines; empty: none
  // Detection (set_detector): lost results in a row before a frame goes to detection instead of
  // tracking (near the prediction first, then the whole search), and in Inline mode the
  // modelled time a detection takes (a tracking step's is processing_s).
  int lost_frames_before_detection = 3;
  double detection_processing_s = 0.3;
};

// One tracked frame, given to the caller's hook (overlays, ground-truth comparison) on the control
// thread when the result is published.
struct TrackedFrame {
  std::uint64_t index = 0;
  double exposure_t_s = 0, published_t_s = 0;
  Eigen::Isometry3d predicted_cam_T_obj = Eigen::Isometry3d::Identity();
  const vision::FrameReport* report = nullptr;
  const vision::ModelTracker* tracker = nullptr;
  const hw::CameraFrame* image = nullptr;
  // The frame's status as the loop took it: the tracker's, or Lost when its pose tilted the
  // object away from the down the accelerometer measures (a wrong lock, fusion/learnt_gravity.h).
  vision::TrackStatus status = vision::TrackStatus::Lost;
  bool against_gravity = false;
};
using FrameHook = std::function<void(const TrackedFrame&)>;

struct OnboardSummary {
  std::uint64_t ticks = 0, late_ticks = 0;       // control ticks; ticks started more than a period late
  std::uint64_t frames = 0, tracked = 0, lost = 0;
  // Frames measured from the vision poses extrapolated alone, the predictor's pose having given
  // nothing usable (ModelTracker::track's fallback; `track` counts them as fallback_frames).
  std::uint64_t fallback_frames = 0;
  std::uint64_t imu_samples = 0, imu_rejected = 0;
  std::uint64_t commands_sent = 0, commands_withheld = 0, send_failures = 0;
  std::uint64_t bus_errors = 0, frames_logged = 0, unknown_frames = 0, undecodable_frames = 0;
  std::uint64_t camera_lost = 0, unreadable_frames = 0;  // device gone; frames of a format the tracker cannot read
  std::uint64_t frames_stamped_ahead = 0;  // frames stamped after the loop's clock when taken: exposure taken as then
  double track_ms_median = 0, track_ms_p99 = 0;                 // wall time of the tracking step
  // Program clock. Exposure -> command = the frame's age when the loop takes it (half the
  // exposure, the camera's readout and transfer, up to one tick of polling) + processing + the
  // wait from the result's publication to the command that carries it (result_to_command).
  double exposure_to_command_ms_median = 0, exposure_to_command_ms_max = 0;
  double frame_age_at_take_ms_median = 0;
  double result_to_command_ms_max = 0;
  double tick_ms_median = 0, tick_ms_p99 = 0;                   // wall time of one control tick's work (vision excluded)
  // Deadlines, measured on the control thread alone: how late each tick started after its
  // scheduled time (loop clock: 0 in simulated time), the tick's own work (wall clock, without
  // inline vision), vision latency from exposure to the published result (loop clock), frames
  // the camera gave while vision was busy (dropped: the next job is the newest frame).
  double tick_lateness_us_median = 0, tick_lateness_us_p99 = 0, tick_lateness_us_max = 0;
  double tick_work_us_median = 0, tick_work_us_p99 = 0, tick_work_us_max = 0;
  double vision_latency_ms_median = 0, vision_latency_ms_p99 = 0, vision_latency_ms_max = 0;
  std::uint64_t frames_dropped_vision_busy = 0;
  // Recording (candump, diagnostics) through the recorder's queues: dropped when full, never waited for.
  std::uint64_t log_frames_dropped = 0, log_lines_dropped = 0, log_write_errors = 0;
  std::size_t log_frame_queue_high_water = 0, log_line_queue_high_water = 0;
  std::string threads;  // what each thread got: CPU, scheduling policy, memory lock
  HeadCounters controller;
  JointBacklash backlash_band;  // the band the compensation used at the end: calibrated or estimated online
  ImuAssemblyCounters imu_assembly;
  ClockSyncCounters imu_clock;  // time sync with the IMU: without it no IMU sample can be placed in time
  fusion::PredictorCounters predictor;
  fusion::ArbiterCounters predictor_restarts;  // restarts from a vision pose that overruled the predictor, by reason
  // Acquisition (set_detector): detections run and how many found the object; losses (runs of
  // lost results) and re-acquisitions by detection; when detection first found the object.
  std::uint64_t detections = 0, detections_found = 0, losses = 0, reacquisitions = 0;
  std::uint64_t levelled_to_gravity = 0;  // found poses levelled to the measured up (down learnt)
  // Found turned as the gyro carried the object's orientation, then tracked turned away from it:
  // not taken (fusion/carried_orientation.h).
  std::uint64_t found_turned_away_from_carried = 0;
  std::uint64_t against_gravity = 0;  // poses (tracked or detected) refused as wrong locks: their tilt
  double first_detection_t_s = -1;
  double detect_ms_max = 0;
};

class OnboardLoop {
 public:
  static std::expected<std::unique_ptr<OnboardLoop>, std::string> create(const vision::CadModel& model,
                                                                          const vision::Camera& camera,
                                                                          const OnboardOptions& options,
                                                                          const OnboardPorts& ports);
  ~OnboardLoop();
  // Runs until the clock reads until_s (or a port fails for good). Frames are handed to `hook`.
  std::expected<OnboardSummary, std::string> run(double until_s, const FrameHook& hook = {});
  // The pose tracking starts from (init.csv on the robot, the scenario's start in the simulator).
  void set_initial_pose(double t_s, const Eigen::Isometry3d& cam_T_obj);
  // Detection for a start without set_initial_pose() and after a loss. It runs on the vision
  // stage like a tracking step (never on the control thread when VisionThreads::Thread); the
  // head controller meanwhile has no fresh target and keeps to its safe mode (target_lost).
  void set_detector(std::unique_ptr<vision::Detector> detector);
  // Ends run() after the current tick; safe from a signal handler or another thread.
  void request_stop();

 private:
  struct Impl;
  explicit OnboardLoop(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace epichead::head
