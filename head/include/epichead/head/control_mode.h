#pragma once
// The controller's modes, the faults its watchdog raises, and the events it reports (every
// mode change and every fault raised or cleared, with the reason) for the diagnostics stream.
#include <cstdint>

namespace epichead::head {

enum class ControlMode : std::uint8_t {
  Startup,    // no head state yet: nothing is commanded (the head's position is unknown)
  Stabilise,  // hold the camera's optical axis still in space against body motion (IMU)
  Fixate,     // turn the optical axis toward the tracked target, stabilised in between frames
  Hold,       // keep the joint angles (where the joints come to rest from the current rate)
  Park,       // go to the park angles at the park rate and stay there
};
const char* to_string(ControlMode mode);

// Watchdog faults (bits).
enum class Fault : std::uint8_t {
  None = 0,
  ImuStale = 1u << 0,        // no gyro sample for longer than imu_timeout_s
  HeadStateStale = 1u << 1,  // no head state for longer than head_state_timeout_s
  BusOff = 1u << 2,          // the CAN controller is bus-off: commands cannot be delivered
  TargetLost = 1u << 3,      // Fixate: no valid target observation for longer than target_timeout_s
};
constexpr Fault operator|(Fault a, Fault b) {
  return static_cast<Fault>(static_cast<std::uint8_t>(a) | static_cast<std::uint8_t>(b));
}
constexpr Fault operator&(Fault a, Fault b) {
  return static_cast<Fault>(static_cast<std::uint8_t>(a) & static_cast<std::uint8_t>(b));
}
constexpr Fault operator~(Fault a) { return static_cast<Fault>(~static_cast<std::uint8_t>(a) & 0x0f); }
constexpr bool has(Fault set, Fault f) { return (set & f) != Fault::None; }
// "imu_stale", "bus_off", ... for one bit; "none" for None.
const char* to_string(Fault fault);

// Why the active mode changed.
enum class ModeReason : std::uint8_t {
  Requested,          // the caller asked for a mode
  HeadStateArrived,   // first head state: leaving Startup
  ImuStale,           // Stabilise/Fixate -> Hold
  BusOff,             // any -> the safe mode
  HeadStateStale,     // any -> the safe mode
  TrackingLost,       // Fixate -> Stabilise
  TrackingLostLong,   // lost for longer than lost_to_hold_s: -> Hold
  Recovered,          // the fault that forced the mode cleared: back toward the requested mode
  TrackingRecovered,  // a valid target again: back to Fixate
};
const char* to_string(ModeReason reason);

enum class EventKind : std::uint8_t { ModeChanged, FaultRaised, FaultCleared, Parked };
const char* to_string(EventKind kind);

struct HeadEvent {
  double t_s = 0;
  EventKind kind = EventKind::ModeChanged;
  ControlMode from = ControlMode::Startup, to = ControlMode::Startup;  // ModeChanged
  ModeReason reason = ModeReason::Requested;                           // ModeChanged
  Fault fault = Fault::None;                                           // FaultRaised / FaultCleared
};

}  // namespace epichead::head
