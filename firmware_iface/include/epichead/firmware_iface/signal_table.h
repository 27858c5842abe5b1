#pragma once
// The protocol's signals as data: bit position, width, signedness and scale of every field,
// in the DBC's terms (Intel byte order). The DBC file (firmware_iface/epichead.dbc) is
// checked against this table, and this table against the encoders, by the tests.
#include <cstdint>
#include <span>
#include <string_view>

#include "epichead/firmware_iface/can_ids.h"

namespace epichead::firmware_iface {

struct SignalSpec {
  std::string_view name;   // DBC signal name
  int start_bit;           // LSB, Intel order: bit b is bit (b % 8) of byte (b / 8)
  int length;              // bits
  bool is_signed;
  double factor;           // physical = raw * factor + offset
  double offset;
  double min, max;         // physical range the field can carry
  std::string_view unit;   // DBC unit string
};

// The signals of one message type, in the order of EncodedFrame::clipped bits.
std::span<const SignalSpec> signal_table(MessageType type);

// "ImuGyro" -> DBC message name is the same; the DBC describes the default nodes
// (TimeSyncReply from the IMU and the head, Heartbeat of controller, IMU and head).

}  // namespace epichead::firmware_iface
