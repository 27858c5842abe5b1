#pragma once
// The closed-loop simulated world behind the hardware ports: body motion, the pan/tilt head
// following the HeadCommand frames it receives, the IMU on the camera sending frames at 1 kHz,
// the camera rendering from the resulting pose, CAN bus timing and the scenario's faults.
//
// Time is simulated and moves only through advance_to() (or a port call that waits, which
// advances it by the wait): the onboard loop sleeps by calling advance_to(next_tick_s) -- the
// hw::Clock port has no sleep, so clock() returns a Clock whose now_s() is the simulated time --
// then polls bus() and camera() with timeout 0 and sends commands with bus().send(). Time spent
// computing is charged by the caller advancing the clock. Everything is deterministic: the same
// scenario, seed and sequence of calls give identical bytes on the bus and identical images.
//
//   world_T_cam(t) = world_T_body(t) * body_T_cam(mount, output joint angles(t))   (head_mount.h)
#include <cstdint>
#include <expected>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "epichead/common/ring_buffer.h"
#include "epichead/hw/camera_port.h"
#include "epichead/hw/can_bus.h"
#include "epichead/hw/clock.h"
#include "epichead/sim/head_mount.h"
#include "epichead/sim/occlusion_truth.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sim_camera.h"
#include "epichead/sim/sim_can_bus.h"
#include "epichead/sim/sim_head_node.h"
#include "epichead/sim/sim_imu_node.h"
#include "epichead/vision/camera.h"

namespace epichead::sim {

enum class CameraOutput {
  Render,  // frames rendered with the scenario's scene (about 50 ms per 640 x 480 frame)
  Blank,   // frames with a zero image: timing and ground truth only (fast tests)
};

struct SimWorldOptions {
  CameraOutput camera = CameraOutput::Render;
  int camera_downscale = 1;  // 1, 2, 4 or 8: a smaller camera (intrinsics scaled) for quick runs
  double horizon_s = 0;      // time the run may reach; 0: the scenario's last frame + 1 s
  double history_s = 1.0;    // how far back truth_at() reaches
};

// The true state of the rig at one simulated time.
struct SimTruth {
  double t_s = 0;
  Eigen::Isometry3d world_T_body = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_T_cam = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  HeadAngles joints;                                   // output (camera-side) angles, rates, accelerations
  double pan_motor_rad = 0, tilt_motor_rad = 0;        // motor (encoder) side: differs by backlash
  Eigen::Vector3d cam_rate_radps = Eigen::Vector3d::Zero();  // camera angular rate, camera axes
  Eigen::Vector3d cam_specific_force_mps2 = Eigen::Vector3d::Zero();  // what an ideal IMU on the camera reads
};

struct SimWorldStats {
  std::uint64_t time_syncs_answered = 0;  // TimeSyncRequest frames the nodes answered
  std::uint64_t host_frames_ignored = 0;  // host frames no node listens to
};

class SimWorld {
 public:
  // Builds the world at t = 0 with the head at the scenario's fixed angles (aim or head_deg).
  // Errors: unknown scene, unreadable camera, bad options.
  static std::expected<std::unique_ptr<SimWorld>, std::string> create(const Scenario& scenario,
                                                                      const SimWorldOptions& options = {});
  ~SimWorld();
  SimWorld(const SimWorld&) = delete;
  SimWorld& operator=(const SimWorld&) = delete;

  double now_s() const { return now_s_; }
  double horizon_s() const { return horizon_s_; }
  // Runs the world up to t_s. An earlier time is an error (time never goes back), as is a time
  // beyond the horizon; the world is then unchanged.
  std::expected<void, std::string> advance_to(double t_s);

  // The ports the onboard loop uses.
  hw::Clock& clock();
  hw::CanBus& bus();
  hw::CameraPort& camera();

  // Ground truth at t_s in [now - history_s, now]; outside: an error saying the range.
  std::expected<SimTruth, std::string> truth_at(double t_s) const;

  // Whether occluders (a cover board) hide the whole object at truth.t_s, seen from the true
  // camera then (occlusion_truth.h; `truth` from truth_at). False for a world built without a
  // scene (CameraOutput::Blank with a given aim and no covers).
  bool object_hidden(const SimTruth& truth);

  const Scenario& scenario() const { return scenario_; }
  const vision::Camera& camera_model() const { return camera_model_; }
  const Eigen::Isometry3d& world_T_obj() const { return world_T_obj_; }
  const FaultPlan& faults() const { return faults_; }
  const SimCanBus& sim_bus() const;
  const SimCamera& sim_camera() const;
  const SimHeadNode& head_node() const { return *head_; }
  const SimImuNode& imu_node() const { return *imu_; }
  const SimWorldStats& stats() const { return stats_; }

 private:
  SimWorld(const Scenario& scenario, const SimWorldOptions& options);
  void run_until(double t_s);
  void deliver_to_nodes(const firmware_iface::CanFrame& frame, double t_s);
  Kinematics world_T_cam_motion(double t_s, const HeadAngles& joints) const;

  class Clock;
  Scenario scenario_;
  SimWorldOptions options_;
  FaultPlan faults_;
  Trajectory body_;
  vision::Camera camera_model_;
  Eigen::Isometry3d world_T_obj_ = Eigen::Isometry3d::Identity();
  double now_s_ = 0, horizon_s_ = 0;
  std::unique_ptr<Clock> clock_;
  std::unique_ptr<SimCanBus> bus_;
  std::unique_ptr<SimHeadNode> head_;
  std::unique_ptr<SimImuNode> imu_;
  std::unique_ptr<SimCamera> camera_;
  std::optional<OcclusionTruth> occlusion_;  // with a scene
  // Servo ticks, newest last, kept for history_s (truth_at, the camera's exposures); a new tick
  // overwrites the oldest.
  common::RingBuffer<HeadTick> history_;
  std::int64_t tick_index_ = 0;   // next servo tick: tick_index_ / servo_rate_hz
  std::int64_t state_index_ = 0, status_index_ = 0, imu_beat_index_ = 0, head_beat_index_ = 0;
  SimWorldStats stats_;
};

}  // namespace epichead::sim
