#pragma once
// The protocol's 11-bit CAN identifiers. Lower id = higher bus priority, so the blocks are
// ordered by how much lateness hurts: time sync (its latency is the measurement), head
// command, IMU samples, head state, heartbeats. Devices are nodes 1..15 (controller = 0);
// a per-node message carries the node number in its low 4 bits.
//
//   0x080          TimeSyncRequest  controller -> all devices
//   0x081..0x08F   TimeSyncReply    device node n answers on 0x080 + n
//   0x100          HeadCommand      controller -> head
//   0x110          ImuGyro          IMU
//   0x111          ImuAccel         IMU
//   0x120          HeadState        head: angles, rates
//   0x121          HeadStatus       head: motor currents, fault bits, temperature
//   0x700..0x70F   Heartbeat        node n on 0x700 + n (0 = controller)
#include <cstdint>
#include <optional>
#include <string_view>

namespace epichead::firmware_iface {

inline constexpr std::uint32_t kIdTimeSyncRequest = 0x080;
inline constexpr std::uint32_t kIdTimeSyncReplyBase = 0x080;  // + node (1..15)
inline constexpr std::uint32_t kIdHeadCommand = 0x100;
inline constexpr std::uint32_t kIdImuGyro = 0x110;
inline constexpr std::uint32_t kIdImuAccel = 0x111;
inline constexpr std::uint32_t kIdHeadState = 0x120;
inline constexpr std::uint32_t kIdHeadStatus = 0x121;
inline constexpr std::uint32_t kIdHeartbeatBase = 0x700;  // + node (0..15)

inline constexpr std::uint8_t kNodeController = 0;
inline constexpr std::uint8_t kNodeImu = 1;    // default node numbers of the shipped firmware
inline constexpr std::uint8_t kNodeHead = 2;
inline constexpr std::uint8_t kMaxNode = 15;

// Every payload of the protocol is a classic CAN frame of exactly this many bytes.
inline constexpr std::uint8_t kFrameLength = 8;

enum class MessageType : std::uint8_t {
  TimeSyncRequest,
  TimeSyncReply,
  HeadCommand,
  ImuGyro,
  ImuAccel,
  HeadState,
  HeadStatus,
  Heartbeat,
};
inline constexpr int kMessageTypeCount = 8;

struct MessageId {
  MessageType type;
  std::uint8_t node;  // sender (or addressee of a request: 0 = broadcast)
};

// The message an 11-bit id stands for, or nothing for an id outside the protocol.
std::optional<MessageId> classify_id(std::uint32_t id);

// The id of a message type sent by / to `node` (node ignored for fixed ids).
std::uint32_t message_can_id(MessageType type, std::uint8_t node = 0);

// "ImuGyro" etc.: the names used in the DBC, the docs and the replay report.
std::string_view to_string(MessageType type);

}  // namespace epichead::firmware_iface
