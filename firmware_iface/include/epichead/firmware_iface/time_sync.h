#pragma once
// Time synchronisation between the controller's clock and each device's clock. The
// controller broadcasts a request with a sequence number and its own clock; each device
// answers with the same sequence number and its own clock at the instant it received the
// request. With the controller's send and receive times t0, t1 and the device time d, the
// offset device - controller is d - (t0 + t1) / 2 (CAN delays are symmetric to a bit time).
// Clocks are 48-bit microsecond counters (8.9 years).
//
// Request 0x080 and reply 0x080+node, 8 bytes:
//   byte 0      sequence    uint8
//   byte 1      reserved    must be 0
//   bytes 2-7   stamp_us    uint48, controller clock (request) / device clock (reply)
#include <cstdint>
#include <expected>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr std::uint64_t kTimeSyncStampMask = (std::uint64_t{1} << 48) - 1;

struct TimeSyncRequest {
  std::uint8_t sequence = 0;
  std::uint64_t controller_stamp_us = 0;  // sent modulo 2^48
};

struct TimeSyncReply {
  std::uint8_t node = 1;  // the answering device (1..15), from the CAN id
  std::uint8_t sequence = 0;
  std::uint64_t device_stamp_us = 0;  // device clock when the request arrived, modulo 2^48
};

std::expected<EncodedFrame, WireError> encode(const TimeSyncRequest& m);
std::expected<EncodedFrame, WireError> encode(const TimeSyncReply& m);
std::expected<TimeSyncRequest, WireError> decode_time_sync_request(const CanFrame& frame);
std::expected<TimeSyncReply, WireError> decode_time_sync_reply(const CanFrame& frame);

}  // namespace epichead::firmware_iface
