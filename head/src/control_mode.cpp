#include "epichead/head/control_mode.h"

namespace epichead::head {

const char* to_string(ControlMode mode) {
  switch (mode) {
    case ControlMode::Startup: return "startup";
    case ControlMode::Stabilise: return "stabilise";
    case ControlMode::Fixate: return "fixate";
    case ControlMode::Hold: return "hold";
    case ControlMode::Park: return "park";
  }
  return "unknown";
}

const char* to_string(Fault fault) {
  switch (fault) {
    case Fault::None: return "none";
    case Fault::ImuStale: return "imu_stale";
    case Fault::HeadStateStale: return "head_state_stale";
    case Fault::BusOff: return "bus_off";
    case Fault::TargetLost: return "target_lost";
  }
  return "several";
}

const char* to_string(ModeReason reason) {
  switch (reason) {
    case ModeReason::Requested: return "requested";
    case ModeReason::HeadStateArrived: return "head_state_arrived";
    case ModeReason::ImuStale: return "imu_stale";
    case ModeReason::BusOff: return "bus_off";
    case ModeReason::HeadStateStale: return "head_state_stale";
    case ModeReason::TrackingLost: return "tracking_lost";
    case ModeReason::TrackingLostLong: return "tracking_lost_long";
    case ModeReason::Recovered: return "recovered";
    case ModeReason::TrackingRecovered: return "tracking_recovered";
  }
  return "unknown";
}

const char* to_string(EventKind kind) {
  switch (kind) {
    case EventKind::ModeChanged: return "mode_changed";
    case EventKind::FaultRaised: return "fault_raised";
    case EventKind::FaultCleared: return "fault_cleared";
    case EventKind::Parked: return "parked";
  }
  return "unknown";
}

}  // namespace epichead::head
