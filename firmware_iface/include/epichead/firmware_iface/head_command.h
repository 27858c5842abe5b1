#pragma once
// Controller -> head: where the pan/tilt joints should be and how fast they should move.
//
// HeadCommand 0x100, 8 bytes, little-endian (Intel) bit fields:
//   bits 0-3    counter          uint4, rolling
//   bits 4-7    mode             HeadMode (0..3; other values rejected)
//   bits 8-23   pan_angle        int16, 1e-4 rad/LSB  (+-3.2767 rad = +-187.7 deg)
//   bits 24-39  tilt_angle       int16, 1e-4 rad/LSB
//   bits 40-51  pan_rate         int12, 0.005 rad/s/LSB (+-10.24 rad/s = +-587 deg/s)
//   bits 52-63  tilt_rate        int12, 0.005 rad/s/LSB
#include <cstdint>
#include <expected>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/head_mode.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr double kHeadAngleRadPerLsb = 1e-4;
inline constexpr double kHeadRateRadpsPerLsb = 0.005;

// Head joint fields saturated on decode (raw value at a limit): bit 0 pan angle, 1 tilt
// angle, 2 pan rate, 3 tilt rate.
using HeadJointMask = std::uint8_t;

struct HeadCommand {
  std::uint8_t counter = 0;  // rolling, sent modulo 16
  HeadMode mode = HeadMode::Off;
  double pan_rad = 0, tilt_rad = 0;
  double pan_rate_radps = 0, tilt_rate_radps = 0;
  HeadJointMask saturated = 0;  // decode only
};

std::expected<EncodedFrame, WireError> encode(const HeadCommand& m);
std::expected<HeadCommand, WireError> decode_head_command(const CanFrame& frame);

}  // namespace epichead::firmware_iface
