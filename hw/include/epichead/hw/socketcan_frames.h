#pragma once
// Conversions between the kernel's SocketCAN structures and the project's CanFrame, as pure
// functions so they are tested without a CAN interface: frames both ways, error-frame classes
// to the controller state, the receive metadata (kernel time stamp, SO_RXQ_OVFL drop count)
// carried in a recvmsg() control buffer, and the id filters.
#include <linux/can.h>
#include <sys/socket.h>

#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <string>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/hw/can_bus.h"

namespace epichead::hw {

// A kernel frame as read from a CAN_RAW socket; nbytes is what the read returned (CAN_MTU for a
// classic frame, CANFD_MTU for an FD frame). Anything else, or a length past the frame's
// maximum, is an error that says what was wrong.
std::expected<CanFrame, std::string> from_kernel_frame(const canfd_frame& kernel, std::size_t nbytes);

// Fills `kernel` for writing and returns how many bytes to write (CAN_MTU or CANFD_MTU).
// Refuses frames no controller can send: id too large for its format, length past 8 (classic)
// or not an FD size, remote FD frames, error frames.
std::expected<std::size_t, std::string> to_kernel_frame(const CanFrame& frame, canfd_frame& kernel);

// What one error frame says (linux/can/error.h): its classes and the state it moves to.
struct CanErrorReport {
  std::uint32_t classes = 0;               // CAN_ERR_* bits of the id (CAN_ERR_BUSOFF, ...)
  std::optional<CanBusState> state;        // the controller state it reports, if it reports one
  std::optional<std::uint8_t> tx_error_count, rx_error_count;  // when CAN_ERR_CNT is set
};
CanErrorReport classify_error_frame(const CanFrame& frame);

// Metadata the kernel attaches to a received frame.
struct CanReceiveMeta {
  std::optional<std::int64_t> stamp_us;      // SO_TIMESTAMP / SO_TIMESTAMPNS (CLOCK_REALTIME)
  std::optional<std::uint32_t> dropped_total;  // SO_RXQ_OVFL: frames dropped on this socket so far
};
// Reads the control messages of a recvmsg() result; ignores unknown or truncated ones.
CanReceiveMeta parse_receive_meta(const msghdr& message);

// Which ids a socket receives. A frame passes when (its id & mask) == (id & mask) and its
// format matches; no filters at all means every frame.
enum class CanIdFormat { Any, Standard, Extended };
struct CanIdFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  CanIdFormat format = CanIdFormat::Any;
};
can_filter to_kernel_filter(const CanIdFilter& filter);

}  // namespace epichead::hw
