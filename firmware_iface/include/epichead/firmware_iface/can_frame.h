#pragma once
// One CAN frame as it is on the bus (classic CAN 2.0 or CAN FD), independent of how it was
// received: the value type that the protocol encodes into, drivers send and receive, logs
// record and the simulator's bus carries.
#include <array>
#include <cstdint>

namespace epichead::firmware_iface {

inline constexpr int kCanMaxData = 8;     // classic CAN
inline constexpr int kCanFdMaxData = 64;  // CAN FD

// Frame kinds and flags as a small bit set (a frame is data unless remote or error).
enum class CanFlags : std::uint8_t {
  None = 0,
  Extended = 1 << 0,  // 29-bit identifier (else 11-bit)
  Remote = 1 << 1,    // remote transmission request: no data
  Error = 1 << 2,     // an error frame reported by the controller (id holds the error class)
  Fd = 1 << 3,        // CAN FD frame (up to 64 data bytes)
  BitRateSwitch = 1 << 4,  // CAN FD: data phase at the higher bit rate
  ErrorStateIndicator = 1 << 5,  // CAN FD: sender is error passive
};
constexpr CanFlags operator|(CanFlags a, CanFlags b) {
  return static_cast<CanFlags>(static_cast<std::uint8_t>(a) | static_cast<std::uint8_t>(b));
}
constexpr CanFlags operator&(CanFlags a, CanFlags b) {
  return static_cast<CanFlags>(static_cast<std::uint8_t>(a) & static_cast<std::uint8_t>(b));
}
constexpr bool has(CanFlags set, CanFlags flag) { return (set & flag) != CanFlags::None; }

struct CanFrame {
  std::uint32_t id = 0;  // 11 or 29 bits (without the Linux EFF/RTR/ERR flag bits)
  CanFlags flags = CanFlags::None;
  std::uint8_t len = 0;  // data length in bytes: 0..8, or 0..64 for FD (one of the FD sizes)
  std::array<std::uint8_t, kCanFdMaxData> data{};

  bool extended() const { return has(flags, CanFlags::Extended); }
  bool remote() const { return has(flags, CanFlags::Remote); }
  bool error() const { return has(flags, CanFlags::Error); }
  bool fd() const { return has(flags, CanFlags::Fd); }
};

// Why no CAN bus can carry this frame (a string literal), or nullptr if one can: an FD or
// error frame marked remote, an error frame that is FD or has an 11/29-bit id format, BRS or
// ESI on a classic frame, an id wider than its format, a length no DLC gives. The candump
// reader rejects these and the writer refuses them, so what is written reads back the same.
const char* impossible_frame_reason(const CanFrame& frame);

// A frame with the time it was seen on the bus (kernel receive time, log time or simulated
// time), in integer microseconds since the clock's epoch: exact for a log's sec.usec stamps.
struct StampedCanFrame {
  std::int64_t stamp_us = 0;
  CanFrame frame;
};

}  // namespace epichead::firmware_iface
