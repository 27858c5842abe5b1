#include "epichead/firmware_iface/can_ids.h"

namespace epichead::firmware_iface {

std::optional<MessageId> classify_id(std::uint32_t id) {
  switch (id) {
    case kIdTimeSyncRequest: return MessageId{MessageType::TimeSyncRequest, 0};
    case kIdHeadCommand: return MessageId{MessageType::HeadCommand, kNodeHead};
    case kIdImuGyro: return MessageId{MessageType::ImuGyro, kNodeImu};
    case kIdImuAccel: return MessageId{MessageType::ImuAccel, kNodeImu};
    case kIdHeadState: return MessageId{MessageType::HeadState, kNodeHead};
    case kIdHeadStatus: return MessageId{MessageType::HeadStatus, kNodeHead};
    default: break;
  }
  if (id > kIdTimeSyncReplyBase && id <= kIdTimeSyncReplyBase + kMaxNode)
    return MessageId{MessageType::TimeSyncReply, static_cast<std::uint8_t>(id - kIdTimeSyncReplyBase)};
  if (id >= kIdHeartbeatBase && id <= kIdHeartbeatBase + kMaxNode)
    return MessageId{MessageType::Heartbeat, static_cast<std::uint8_t>(id - kIdHeartbeatBase)};
  return std::nullopt;
}

std::uint32_t message_can_id(MessageType type, std::uint8_t node) {
  switch (type) {
    case MessageType::TimeSyncRequest: return kIdTimeSyncRequest;
    case MessageType::TimeSyncReply: return kIdTimeSyncReplyBase + (node & 0xF);
    case MessageType::HeadCommand: return kIdHeadCommand;
    case MessageType::ImuGyro: return kIdImuGyro;
    case MessageType::ImuAccel: return kIdImuAccel;
    case MessageType::HeadState: return kIdHeadState;
    case MessageType::HeadStatus: return kIdHeadStatus;
    case MessageType::Heartbeat: return kIdHeartbeatBase + (node & 0xF);
  }
  return 0;
}

std::string_view to_string(MessageType type) {
  switch (type) {
    case MessageType::TimeSyncRequest: return "TimeSyncRequest";
    case MessageType::TimeSyncReply: return "TimeSyncReply";
    case MessageType::HeadCommand: return "HeadCommand";
    case MessageType::ImuGyro: return "ImuGyro";
    case MessageType::ImuAccel: return "ImuAccel";
    case MessageType::HeadState: return "HeadState";
    case MessageType::HeadStatus: return "HeadStatus";
    case MessageType::Heartbeat: return "Heartbeat";
  }
  return "?";
}

}  // namespace epichead::firmware_iface
