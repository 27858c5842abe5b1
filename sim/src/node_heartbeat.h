#pragma once
// The heartbeat frame the simulated firmware nodes (IMU, head) send once a second: their state,
// the protocol version and the uptime, as the real nodes' firmware does (docs/protocol.md).
#include <algorithm>
#include <cstdint>

#include "epichead/firmware_iface/heartbeat.h"
#include "epichead/firmware_iface/version.h"

namespace epichead::sim {

inline firmware_iface::CanFrame node_heartbeat_frame(std::uint8_t node, firmware_iface::NodeState state, double t_s) {
  firmware_iface::Heartbeat h;
  h.node = node;
  h.state = state;
  h.protocol_version = firmware_iface::kProtocolVersion;
  h.firmware_major = 1;
  h.uptime_s = static_cast<std::uint32_t>(std::max(0.0, t_s));
  auto e = firmware_iface::encode(h);
  return e ? e->frame : firmware_iface::CanFrame{};
}

}  // namespace epichead::sim
