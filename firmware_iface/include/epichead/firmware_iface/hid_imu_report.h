#pragma once
// The IMU sample as a USB HID input report (vendor-defined usage page 0xFF00), for the hidapi
// driver and the simulator. Layout (18 bytes, little-endian, as hid_read returns it with the
// report ID first):
//   byte 0      report ID = 0x01
//   byte 1      counter        uint8, rolling
//   bytes 2-5   stamp_us       uint32, device clock in microseconds (wraps)
//   bytes 6-11  gyro x, y, z   int16, kGyroRadpsPerLsb  (imu_scale.h)
//   bytes 12-17 accel x, y, z  int16, kAccelMps2PerLsb
// docs/protocol.md shows the report descriptor item by item.
#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <span>

#include "epichead/firmware_iface/imu_sample.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr std::uint8_t kHidImuReportId = 0x01;
inline constexpr std::size_t kHidImuReportSize = 18;  // including the report ID byte
inline constexpr std::uint16_t kHidUsagePageVendor = 0xFF00;

// The device's HID report descriptor: one application collection with one input report.
inline constexpr auto kHidImuReportDescriptor = std::to_array<std::uint8_t>({
    0x06, 0x00, 0xFF,  // Usage Page (Vendor Defined 0xFF00)
    0x09, 0x01,        // Usage (0x01: IMU)
    0xA1, 0x01,        // Collection (Application)
    0x85, 0x01,        //   Report ID (1)
    0x15, 0x00,        //   Logical Minimum (0)
    0x26, 0xFF, 0x00,  //   Logical Maximum (255)
    0x75, 0x08,        //   Report Size (8)
    0x09, 0x02,        //   Usage (0x02: counter)
    0x95, 0x01,        //   Report Count (1)
    0x81, 0x02,        //   Input (Data, Variable, Absolute)
    0x09, 0x03,        //   Usage (0x03: stamp_us, 4 bytes little-endian)
    0x95, 0x04,        //   Report Count (4)
    0x81, 0x02,        //   Input (Data, Variable, Absolute)
    0x16, 0x00, 0x80,  //   Logical Minimum (-32768)
    0x26, 0xFF, 0x7F,  //   Logical Maximum (32767)
    0x75, 0x10,        //   Report Size (16)
    0x95, 0x03,        //   Report Count (3)
    0x09, 0x04,        //   Usage (0x04: gyro x, y, z)
    0x81, 0x02,        //   Input (Data, Variable, Absolute)
    0x09, 0x05,        //   Usage (0x05: accel x, y, z)
    0x81, 0x02,        //   Input (Data, Variable, Absolute); Report Count 3 still holds
    0xC0,              // End Collection
});

// Decodes a report as hid_read returns it (report ID first). Rejects a wrong report ID and a
// report shorter than kHidImuReportSize; longer input (a padded USB packet) is accepted.
std::expected<ImuSample, WireError> decode_hid_imu_report(std::span<const std::uint8_t> bytes);

struct HidImuReport {
  std::array<std::uint8_t, kHidImuReportSize> bytes{};
  ImuAxisMask clipped = 0;  // axes whose value was outside the field's range and was clipped
};

// Encodes a sample (tests, simulator). Rejects NaN or infinite values; clips and reports
// values outside the int16 range.
std::expected<HidImuReport, WireError> encode_hid_imu_report(const ImuSample& sample);

}  // namespace epichead::firmware_iface
