#include "epichead/firmware_iface/protocol.h"

namespace epichead::firmware_iface {

namespace {
template <typename T>
std::expected<Message, WireError> widen(std::expected<T, WireError> r) {
  if (!r) return std::unexpected(r.error());
  return Message{std::in_place_type<T>, *r};
}
}  // namespace

std::expected<Message, WireError> decode(const CanFrame& frame) {
  // A 29-bit id is another protocol's (DroneCAN, J1939) even when its value is one of ours.
  const auto id = frame.extended() ? std::nullopt : classify_id(frame.id);
  if (!id) return std::unexpected(WireError{WireErrorKind::UnknownId, frame.id, -1, {}, 0});
  switch (id->type) {
    case MessageType::TimeSyncRequest: return widen(decode_time_sync_request(frame));
    case MessageType::TimeSyncReply: return widen(decode_time_sync_reply(frame));
    case MessageType::HeadCommand: return widen(decode_head_command(frame));
    case MessageType::ImuGyro: return widen(decode_imu_gyro(frame));
    case MessageType::ImuAccel: return widen(decode_imu_accel(frame));
    case MessageType::HeadState: return widen(decode_head_state(frame));
    case MessageType::HeadStatus: return widen(decode_head_status(frame));
    case MessageType::Heartbeat: return widen(decode_heartbeat(frame));
  }
  return std::unexpected(WireError{WireErrorKind::UnknownId, frame.id, -1, {}, 0});
}

}  // namespace epichead::firmware_iface
