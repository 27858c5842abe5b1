#pragma once
// Faults injected into a closed-loop run, from the scenario's `fault` lines: each is a time
// window [start_s, start_s + duration_s) of simulated time.
#include <string_view>
#include <vector>

#include "epichead/sim/head_dynamics.h"

namespace epichead::sim {

enum class FaultKind {
  imu_dropout,   // the IMU node sends nothing (its counter keeps counting: the host sees a gap)
  bus_off,       // the host's CAN controller is bus-off: receive() errors, send() fails, frames lost
  camera_stall,  // frames whose exposure starts in the window never arrive
  stuck_joint,   // one joint is blocked: it does not move, draws stall current, reports over-current
};
std::string_view to_string(FaultKind kind);

struct FaultWindow {
  FaultKind kind = FaultKind::imu_dropout;
  double start_s = 0, duration_s = 0;
  Joint joint = Joint::pan;  // stuck_joint only

  bool covers(double t_s) const { return t_s >= start_s && t_s < start_s + duration_s; }
};

class FaultPlan {
 public:
  FaultPlan() = default;
  explicit FaultPlan(std::vector<FaultWindow> windows) : windows_(std::move(windows)) {}

  // Whether a fault of this kind is on at t_s (stuck_joint: for that joint).
  bool active(FaultKind kind, double t_s) const;
  bool joint_stuck(Joint joint, double t_s) const;
  // How many windows of this kind have started at or before t_s (bus-off events so far).
  int started(FaultKind kind, double t_s) const;
  // The window of this kind covering t_s, or nullptr.
  const FaultWindow* window_at(FaultKind kind, double t_s) const;
  const std::vector<FaultWindow>& windows() const { return windows_; }

 private:
  std::vector<FaultWindow> windows_;
};

}  // namespace epichead::sim
