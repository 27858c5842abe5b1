#pragma once
// Any frame of the protocol decoded by its id: the entry point for the onboard loop, the
// replay tool and the simulator. No allocation: the result is a variant of value types.
#include <expected>
#include <variant>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/head_command.h"
#include "epichead/firmware_iface/head_state.h"
#include "epichead/firmware_iface/head_status.h"
#include "epichead/firmware_iface/heartbeat.h"
#include "epichead/firmware_iface/imu_frames.h"
#include "epichead/firmware_iface/time_sync.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

// Alternatives in MessageType order, so message.index() == static_cast<int>(type).
using Message = std::variant<TimeSyncRequest, TimeSyncReply, HeadCommand, ImuGyro, ImuAccel, HeadState,
                             HeadStatus, Heartbeat>;

// Decodes a frame of the protocol; WireErrorKind::UnknownId for a frame of another protocol.
std::expected<Message, WireError> decode(const CanFrame& frame);

inline MessageType message_type(const Message& m) { return static_cast<MessageType>(m.index()); }

}  // namespace epichead::firmware_iface
