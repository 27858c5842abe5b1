#include "epichead/firmware_iface/heartbeat.h"

#include "frame_codec.h"

namespace epichead::firmware_iface {

using detail::Packer;
using detail::raw_of;

namespace {
constexpr int kState = 0, kProtocol = 1, kMajor = 2, kMinor = 3, kPatch = 4, kUptime = 5;
}

std::string_view to_string(NodeState state) {
  switch (state) {
    case NodeState::Booting: return "booting";
    case NodeState::Operational: return "operational";
    case NodeState::Degraded: return "degraded";
    case NodeState::Fault: return "fault";
  }
  return "?";
}

std::expected<EncodedFrame, WireError> encode(const Heartbeat& m) {
  const auto specs = signal_table(MessageType::Heartbeat);
  const auto state = static_cast<std::uint8_t>(m.state);
  if (state >= kNodeStateCount)
    return std::unexpected(detail::out_of_range(kIdHeartbeatBase + m.node, specs[kState], state));
  if (m.node > kMaxNode)
    return std::unexpected(WireError{WireErrorKind::OutOfRange, kIdHeartbeatBase, -1, "node", m.node});
  Packer p(message_can_id(MessageType::Heartbeat, m.node), MessageType::Heartbeat);
  p.raw(kState, state);
  p.raw(kProtocol, m.protocol_version);
  p.raw(kMajor, m.firmware_major);
  p.raw(kMinor, m.firmware_minor);
  p.raw(kPatch, m.firmware_patch);
  p.raw(kUptime, m.uptime_s);
  return p.finish();
}

std::expected<Heartbeat, WireError> decode_heartbeat(const CanFrame& frame) {
  const auto payload = detail::node_payload_of(frame, MessageType::Heartbeat);
  if (!payload) return std::unexpected(payload.error());
  const MessageId* id = &payload->id;
  const std::uint64_t w = payload->word;
  const auto specs = signal_table(MessageType::Heartbeat);
  const std::int64_t state = raw_of(w, specs[kState]);
  if (state >= kNodeStateCount) return std::unexpected(detail::out_of_range(frame.id, specs[kState], state));
  Heartbeat m;
  m.node = id->node;
  m.state = static_cast<NodeState>(state);
  m.protocol_version = static_cast<std::uint8_t>(raw_of(w, specs[kProtocol]));
  m.firmware_major = static_cast<std::uint8_t>(raw_of(w, specs[kMajor]));
  m.firmware_minor = static_cast<std::uint8_t>(raw_of(w, specs[kMinor]));
  m.firmware_patch = static_cast<std::uint8_t>(raw_of(w, specs[kPatch]));
  m.uptime_s = static_cast<std::uint32_t>(raw_of(w, specs[kUptime]));
  return m;
}

}  // namespace epichead::firmware_iface
