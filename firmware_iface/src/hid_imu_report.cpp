#include "epichead/firmware_iface/hid_imu_report.h"

#include <cmath>

#include "epichead/firmware_iface/fixed_point.h"
#include "le_bytes.h"

namespace epichead::firmware_iface {

using detail::get_i16;
using detail::get_u32;
using detail::put_u16;
using detail::put_uint;

std::expected<ImuSample, WireError> decode_hid_imu_report(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return std::unexpected(WireError{WireErrorKind::ShortFrame, kHidImuReportId, 0, "report id", 0});
  if (bytes[0] != kHidImuReportId)
    return std::unexpected(WireError{WireErrorKind::BadReportId, bytes[0], 0, "report id", bytes[0]});
  if (bytes.size() < kHidImuReportSize)
    return std::unexpected(WireError{WireErrorKind::ShortFrame, kHidImuReportId, static_cast<int>(bytes.size()), "",
                                     static_cast<std::int64_t>(bytes.size())});
  const std::uint8_t* p = bytes.data();
  ImuSample s;
  s.counter = p[1];
  s.stamp_us = get_u32(p + 2);
  for (int axis = 0; axis < 3; ++axis) {
    const std::int16_t g = get_i16(p + 6 + 2 * axis);
    const std::int16_t a = get_i16(p + 12 + 2 * axis);
    s.gyro_radps[axis] = g * kGyroRadpsPerLsb;
    s.accel_mps2[axis] = a * kAccelMps2PerLsb;
    if (g == INT16_MIN || g == INT16_MAX) s.saturated |= static_cast<ImuAxisMask>(1u << axis);
    if (a == INT16_MIN || a == INT16_MAX) s.saturated |= static_cast<ImuAxisMask>(1u << (3 + axis));
  }
  return s;
}

std::expected<HidImuReport, WireError> encode_hid_imu_report(const ImuSample& sample) {
  HidImuReport r;
  std::uint8_t* p = r.bytes.data();
  p[0] = kHidImuReportId;
  p[1] = sample.counter;
  put_uint(p + 2, 4, sample.stamp_us);
  for (int axis = 0; axis < 3; ++axis) {
    if (!std::isfinite(sample.gyro_radps[axis]))
      return std::unexpected(WireError{WireErrorKind::NotFinite, kHidImuReportId, 6 + 2 * axis, "gyro", 0});
    if (!std::isfinite(sample.accel_mps2[axis]))
      return std::unexpected(WireError{WireErrorKind::NotFinite, kHidImuReportId, 12 + 2 * axis, "accel", 0});
    const Quantized g = quantize(sample.gyro_radps[axis], kGyroRadpsPerLsb, INT16_MIN, INT16_MAX);
    const Quantized a = quantize(sample.accel_mps2[axis], kAccelMps2PerLsb, INT16_MIN, INT16_MAX);
    put_u16(p + 6 + 2 * axis, static_cast<std::uint16_t>(g.raw));
    put_u16(p + 12 + 2 * axis, static_cast<std::uint16_t>(a.raw));
    if (g.clipped) r.clipped |= static_cast<ImuAxisMask>(1u << axis);
    if (a.clipped) r.clipped |= static_cast<ImuAxisMask>(1u << (3 + axis));
  }
  return r;
}

}  // namespace epichead::firmware_iface
