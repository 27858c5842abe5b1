#pragma once
// Fixed-point scales of the IMU fields, the same on CAN (imu_frames.h) and USB HID
// (hid_imu_report.h). Both are int16 and chosen to cover a MEMS IMU's widest ranges
// (gyro +-2000 deg/s, accelerometer +-16 g) with margin:
//   gyro  0.00125 rad/s per LSB: +-40.96 rad/s (+-2347 deg/s), resolution 0.072 deg/s
//   accel 0.005 m/s^2 per LSB:   +-163.8 m/s^2 (+-16.7 g),     resolution 0.51 mg
// A raw value at the int16 limits (-32768 or 32767) is reported as saturated.
#include <cstdint>

namespace epichead::firmware_iface {

inline constexpr double kGyroRadpsPerLsb = 0.00125;
inline constexpr double kAccelMps2PerLsb = 0.005;

// Axes of the IMU fields: the head's camera axes (x right, y down, z forward), as in imu.csv.

// Per-axis bit set: bit 0..2 = x, y, z of the gyro; bit 3..5 = x, y, z of the accelerometer.
using ImuAxisMask = std::uint8_t;
inline constexpr ImuAxisMask kGyroAxesMask = 0x07;
inline constexpr ImuAxisMask kAccelAxesMask = 0x38;

}  // namespace epichead::firmware_iface
