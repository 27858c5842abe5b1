#pragma once
// The IMU's samples on CAN: one frame for the gyro, one for the accelerometer, sent as a
// pair per sample with the same counter and stamp. Scales: imu_scale.h.
//
// ImuGyro 0x110 / ImuAccel 0x111, 8 bytes:
//   bits 0-15, 16-31, 32-47   x, y, z      int16 (camera axes: x right, y down, z forward)
//   bits 48-51                counter      uint4, rolling, +1 per sample
//   bits 52-63                stamp        uint12, device clock in 16 us ticks (wraps every
//                                          65.536 ms; stamp_unwrap.h restores the full time
//                                          from the TimeSyncReply clock or the previous sample)
// Eight bytes hold three int16 axes and 16 bits more: a full microsecond stamp does not fit,
// so the stamp is coarse (16 us, well under an IMU's own sampling jitter) and wraps.
#include <array>
#include <cstdint>
#include <expected>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/imu_scale.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr std::uint32_t kImuStampTickUs = 16;
inline constexpr std::uint32_t kImuStampWrapUs = 4096 * kImuStampTickUs;  // 65536 us
inline constexpr std::uint8_t kImuCounterModulo = 16;

struct ImuVectorFrame {
  std::array<double, 3> value{};  // rad/s (gyro) or m/s^2 (accel)
  std::uint8_t counter = 0;       // sent modulo 16
  std::uint32_t stamp_mod_us = 0; // device clock modulo kImuStampWrapUs, 16 us resolution
  std::uint8_t saturated = 0;     // decode only: bit per axis x, y, z at the int16 limits
};
struct ImuGyro : ImuVectorFrame {};
struct ImuAccel : ImuVectorFrame {};

// Device clock (us, any width) -> the wrapped stamp the frame carries.
constexpr std::uint32_t imu_stamp_mod_us(std::uint64_t device_us) {
  return static_cast<std::uint32_t>(device_us % kImuStampWrapUs) / kImuStampTickUs * kImuStampTickUs;
}

std::expected<EncodedFrame, WireError> encode(const ImuGyro& m);
std::expected<EncodedFrame, WireError> encode(const ImuAccel& m);
std::expected<ImuGyro, WireError> decode_imu_gyro(const CanFrame& frame);
std::expected<ImuAccel, WireError> decode_imu_accel(const CanFrame& frame);

}  // namespace epichead::firmware_iface
