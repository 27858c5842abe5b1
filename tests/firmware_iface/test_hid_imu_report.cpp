// The USB HID IMU input report (hid_imu_report.h): layout, round trip, rejections, descriptor.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "epichead/firmware_iface/hid_imu_report.h"

using namespace epichead::firmware_iface;

TEST_CASE("HID IMU report round trips a sample to half an LSB") {
  ImuSample s;
  s.counter = 250;
  s.stamp_us = 0xDEADBEEF;
  s.gyro_radps = {0.1, -34.9, 2.0};
  s.accel_mps2 = {0.0, 9.80665, -156.9};
  auto r = encode_hid_imu_report(s);
  REQUIRE(r);
  CHECK(r->clipped == 0);
  auto back = decode_hid_imu_report(r->bytes);
  REQUIRE(back);
  CHECK(back->counter == 250);
  CHECK(back->stamp_us == 0xDEADBEEFu);
  for (int i = 0; i < 3; ++i) {
    CHECK(std::abs(back->gyro_radps[i] - s.gyro_radps[i]) <= kGyroRadpsPerLsb / 2 + 1e-12);
    CHECK(std::abs(back->accel_mps2[i] - s.accel_mps2[i]) <= kAccelMps2PerLsb / 2 + 1e-12);
  }
  CHECK(back->saturated == 0);
}

TEST_CASE("HID IMU report bytes follow the documented layout") {
  ImuSample s;
  s.counter = 7;
  s.stamp_us = 0x04030201;
  s.gyro_radps = {kGyroRadpsPerLsb * 2, 0, 0};
  s.accel_mps2 = {0, 0, -kAccelMps2PerLsb};
  auto r = encode_hid_imu_report(s);
  REQUIRE(r);
  const std::vector<std::uint8_t> expected = {0x01, 7, 1, 2, 3, 4, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0xFF, 0xFF};
  CHECK(std::vector<std::uint8_t>(r->bytes.begin(), r->bytes.end()) == expected);
}

TEST_CASE("HID IMU report rejects a wrong report id, a short report and NaN, clips and flags saturation") {
  auto r = encode_hid_imu_report(ImuSample{});
  REQUIRE(r);
  auto bytes = r->bytes;
  bytes[0] = 0x02;
  auto bad_id = decode_hid_imu_report(bytes);
  REQUIRE_FALSE(bad_id);
  CHECK(bad_id.error().kind == WireErrorKind::BadReportId);
  CHECK(bad_id.error().message().find("HID report 0x02") != std::string::npos);

  auto shorter = decode_hid_imu_report(std::span<const std::uint8_t>(r->bytes.data(), 10));
  REQUIRE_FALSE(shorter);
  CHECK(shorter.error().kind == WireErrorKind::ShortFrame);
  CHECK_FALSE(decode_hid_imu_report(std::span<const std::uint8_t>{}));

  std::vector<std::uint8_t> padded(r->bytes.begin(), r->bytes.end());
  padded.resize(64, 0);  // a full USB packet
  CHECK(decode_hid_imu_report(padded));

  ImuSample nan;
  nan.accel_mps2[1] = std::nan("");
  CHECK(encode_hid_imu_report(nan).error().kind == WireErrorKind::NotFinite);

  ImuSample big;
  big.gyro_radps = {100.0, 0, 0};
  big.accel_mps2 = {0, 0, -500.0};
  auto clipped = encode_hid_imu_report(big);
  REQUIRE(clipped);
  CHECK(clipped->clipped == ((1u << 0) | (1u << 5)));
  CHECK(decode_hid_imu_report(clipped->bytes)->saturated == ((1u << 0) | (1u << 5)));
}

TEST_CASE("HID report descriptor declares 17 input bytes after report id 1 on the vendor page") {
  const auto& d = kHidImuReportDescriptor;
  REQUIRE(d.size() >= 7);
  CHECK(d[0] == 0x06);
  CHECK(d[1] == 0x00);
  CHECK(d[2] == 0xFF);  // usage page 0xFF00
  CHECK(d.back() == 0xC0);
  // Walk the short items and add up report size x count at each Input item.
  int bits = 0, size = 0, count = 0, report_id = -1;
  for (std::size_t i = 0; i < d.size();) {
    const std::uint8_t prefix = d[i];
    const int n = (prefix & 3) == 3 ? 4 : (prefix & 3);
    std::uint32_t value = 0;
    for (int k = 0; k < n; ++k) value |= static_cast<std::uint32_t>(d[i + 1 + k]) << (8 * k);
    switch (prefix & 0xFC) {
      case 0x74: size = static_cast<int>(value); break;    // Report Size
      case 0x94: count = static_cast<int>(value); break;   // Report Count
      case 0x84: report_id = static_cast<int>(value); break;
      case 0x80: bits += size * count; break;              // Input
      default: break;
    }
    i += 1 + static_cast<std::size_t>(n);
  }
  CHECK(report_id == kHidImuReportId);
  CHECK(bits == 8 * static_cast<int>(kHidImuReportSize - 1));
}
