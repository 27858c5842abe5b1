#pragma once
// Every node, once a second: that it is alive, its state, the firmware and protocol version.
//
// Heartbeat 0x700+node, 8 bytes:
//   byte 0      state             NodeState (0..3; other values rejected)
//   byte 1      protocol_version  uint8 (version.h kProtocolVersion)
//   bytes 2-4   firmware major, minor, patch   uint8 each
//   bytes 5-7   uptime            uint24, seconds (194 days)
#include <cstdint>
#include <expected>
#include <string_view>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

enum class NodeState : std::uint8_t { Booting = 0, Operational = 1, Degraded = 2, Fault = 3 };
inline constexpr std::uint8_t kNodeStateCount = 4;
std::string_view to_string(NodeState state);

struct Heartbeat {
  std::uint8_t node = 0;  // from the CAN id
  NodeState state = NodeState::Booting;
  std::uint8_t protocol_version = 0;
  std::uint8_t firmware_major = 0, firmware_minor = 0, firmware_patch = 0;
  std::uint32_t uptime_s = 0;  // sent modulo 2^24
};

std::expected<EncodedFrame, WireError> encode(const Heartbeat& m);
std::expected<Heartbeat, WireError> decode_heartbeat(const CanFrame& frame);

}  // namespace epichead::firmware_iface
