#pragma once
// Head -> controller: the measured joint angles and rates and the mode the head is in.
//
// HeadState 0x120, 8 bytes: the same bit layout and scales as HeadCommand (head_command.h):
//   counter uint4 | mode uint4 | pan_angle int16 | tilt_angle int16 | pan_rate int12 | tilt_rate int12
#include <cstdint>
#include <expected>

#include "epichead/firmware_iface/head_command.h"

namespace epichead::firmware_iface {

struct HeadState {
  std::uint8_t counter = 0;  // rolling, sent modulo 16
  HeadMode mode = HeadMode::Off;
  double pan_rad = 0, tilt_rad = 0;
  double pan_rate_radps = 0, tilt_rate_radps = 0;
  HeadJointMask saturated = 0;  // decode only
};

std::expected<EncodedFrame, WireError> encode(const HeadState& m);
std::expected<HeadState, WireError> decode_head_state(const CanFrame& frame);

}  // namespace epichead::firmware_iface
