#include "epichead/firmware_iface/imu_frames.h"

#include "frame_codec.h"

namespace epichead::firmware_iface {

using detail::at_limit;
using detail::Packer;
using detail::raw_of;

namespace {
constexpr int kCounter = 3, kStamp = 4;

std::expected<EncodedFrame, WireError> encode_vector(const ImuVectorFrame& m, std::uint32_t id, MessageType type) {
  Packer p(id, type);
  for (int axis = 0; axis < 3; ++axis) p.value(axis, m.value[static_cast<std::size_t>(axis)]);
  p.raw(kCounter, m.counter);
  p.raw(kStamp, (m.stamp_mod_us % kImuStampWrapUs) / kImuStampTickUs);
  return p.finish();
}

template <typename M>
std::expected<M, WireError> decode_vector(const CanFrame& frame, std::uint32_t id, MessageType type) {
  const auto payload = detail::payload_of(frame, id);
  if (!payload) return std::unexpected(payload.error());
  const std::uint64_t w = *payload;
  const auto specs = signal_table(type);
  M m;
  for (int axis = 0; axis < 3; ++axis) {
    const SignalSpec& s = specs[static_cast<std::size_t>(axis)];
    const std::int64_t raw = raw_of(w, s);
    m.value[static_cast<std::size_t>(axis)] = static_cast<double>(raw) * s.factor;
    if (at_limit(raw, s)) m.saturated |= static_cast<std::uint8_t>(1u << axis);
  }
  m.counter = static_cast<std::uint8_t>(raw_of(w, specs[kCounter]));
  m.stamp_mod_us = static_cast<std::uint32_t>(raw_of(w, specs[kStamp])) * kImuStampTickUs;
  return m;
}
}  // namespace

std::expected<EncodedFrame, WireError> encode(const ImuGyro& m) {
  return encode_vector(m, kIdImuGyro, MessageType::ImuGyro);
}
std::expected<EncodedFrame, WireError> encode(const ImuAccel& m) {
  return encode_vector(m, kIdImuAccel, MessageType::ImuAccel);
}
std::expected<ImuGyro, WireError> decode_imu_gyro(const CanFrame& frame) {
  return decode_vector<ImuGyro>(frame, kIdImuGyro, MessageType::ImuGyro);
}
std::expected<ImuAccel, WireError> decode_imu_accel(const CanFrame& frame) {
  return decode_vector<ImuAccel>(frame, kIdImuAccel, MessageType::ImuAccel);
}

}  // namespace epichead::firmware_iface
