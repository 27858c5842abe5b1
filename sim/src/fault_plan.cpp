#include "epichead/sim/fault_plan.h"

namespace epichead::sim {

std::string_view to_string(FaultKind kind) {
  switch (kind) {
    case FaultKind::imu_dropout: return "imu_dropout";
    case FaultKind::bus_off: return "bus_off";
    case FaultKind::camera_stall: return "camera_stall";
    case FaultKind::stuck_joint: return "stuck_joint";
  }
  return "unknown";
}

const FaultWindow* FaultPlan::window_at(FaultKind kind, double t_s) const {
  for (const FaultWindow& w : windows_) {
    if (w.kind == kind && w.covers(t_s)) return &w;
  }
  return nullptr;
}

bool FaultPlan::active(FaultKind kind, double t_s) const { return window_at(kind, t_s) != nullptr; }

bool FaultPlan::joint_stuck(Joint joint, double t_s) const {
  for (const FaultWindow& w : windows_) {
    if (w.kind == FaultKind::stuck_joint && w.joint == joint && w.covers(t_s)) return true;
  }
  return false;
}

int FaultPlan::started(FaultKind kind, double t_s) const {
  int n = 0;
  for (const FaultWindow& w : windows_) n += w.kind == kind && w.duration_s > 0 && w.start_s <= t_s;
  return n;
}

}  // namespace epichead::sim
