#pragma once
// One IMU sample as the device reports it over USB HID (both sensors at one instant), in SI
// units. On CAN the same sample travels as a gyro frame and an accelerometer frame.
#include <array>
#include <cstdint>

#include "epichead/firmware_iface/imu_scale.h"

namespace epichead::firmware_iface {

struct ImuSample {
  std::uint8_t counter = 0;   // rolling, +1 per sample, wraps 255 -> 0
  std::uint32_t stamp_us = 0; // device clock at the sample, wraps every 2^32 us (71.6 min)
  std::array<double, 3> gyro_radps{};   // camera axes: x right, y down, z forward
  std::array<double, 3> accel_mps2{};   // specific force, same axes
  ImuAxisMask saturated = 0;  // decode: axes whose raw value sat at the int16 limits
};

}  // namespace epichead::firmware_iface
