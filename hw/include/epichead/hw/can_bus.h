#pragma once
// The CAN bus port: what the onboard loop needs from a bus, whether SocketCAN on the robot or
// the simulator's bus. Error frames reported by the controller are delivered as frames with
// CanFlags::Error (so logs keep them) and also folded into stats().state.
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>

#include "epichead/firmware_iface/can_frame.h"

namespace epichead::hw {

using firmware_iface::CanFrame;
using firmware_iface::StampedCanFrame;

enum class CanReceive {
  Frame,    // `out` holds a frame (data, remote or error frame)
  Timeout,  // nothing arrived within the timeout
  Error,    // the bus failed (interface down, socket error): see last_error()
};

// The controller's fault-confinement state, from error frames (ISO 11898-1).
enum class CanBusState { ErrorActive, ErrorWarning, ErrorPassive, BusOff };

struct CanBusStats {
  std::uint64_t rx_frames = 0;         // data and remote frames received
  std::uint64_t rx_error_frames = 0;   // error frames received
  std::uint64_t rx_dropped = 0;        // frames the kernel dropped for a full receive queue
  std::uint64_t rx_malformed = 0;      // frames the driver could not read (wrong size) and skipped
  std::uint64_t tx_frames = 0;         // frames handed to the bus
  std::uint64_t tx_failed = 0;         // sends refused (queue full, bus down, invalid frame)
  std::uint64_t bus_off_events = 0;    // times the controller went bus-off
  CanBusState state = CanBusState::ErrorActive;
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Queues one frame for transmission without blocking; an error says why it was refused.
  virtual std::expected<void, std::string> send(const CanFrame& frame) = 0;
  // Waits up to timeout_s (0: do not wait; negative: wait indefinitely) for the next frame.
  virtual CanReceive receive(StampedCanFrame& out, double timeout_s) = 0;
  virtual CanBusStats stats() const = 0;
  // Why the last receive() returned Error (empty if none did).
  virtual std::string_view last_error() const = 0;
};

std::string_view to_string(CanBusState state);

}  // namespace epichead::hw
