// HeadCommand and HeadState: one bit layout (signal_table.cpp kHeadJoints), two directions.
#include "epichead/firmware_iface/head_command.h"
#include "epichead/firmware_iface/head_state.h"

#include "frame_codec.h"

namespace epichead::firmware_iface {

using detail::at_limit;
using detail::Packer;
using detail::raw_of;

namespace {
constexpr int kCounter = 0, kMode = 1, kPan = 2, kTilt = 3, kPanRate = 4, kTiltRate = 5;

template <typename M>
std::expected<EncodedFrame, WireError> encode_joints(const M& m, std::uint32_t id, MessageType type) {
  const auto mode = static_cast<std::uint8_t>(m.mode);
  if (mode >= kHeadModeCount)
    return std::unexpected(detail::out_of_range(id, signal_table(type)[kMode], mode));
  Packer p(id, type);
  p.raw(kCounter, m.counter);
  p.raw(kMode, mode);
  p.value(kPan, m.pan_rad);
  p.value(kTilt, m.tilt_rad);
  p.value(kPanRate, m.pan_rate_radps);
  p.value(kTiltRate, m.tilt_rate_radps);
  return p.finish();
}

template <typename M>
std::expected<M, WireError> decode_joints(const CanFrame& frame, std::uint32_t id, MessageType type) {
  const auto payload = detail::payload_of(frame, id);
  if (!payload) return std::unexpected(payload.error());
  const std::uint64_t w = *payload;
  const auto specs = signal_table(type);
  const std::int64_t mode = raw_of(w, specs[kMode]);
  if (mode >= kHeadModeCount) return std::unexpected(detail::out_of_range(id, specs[kMode], mode));
  M m;
  m.counter = static_cast<std::uint8_t>(raw_of(w, specs[kCounter]));
  m.mode = static_cast<HeadMode>(mode);
  double* values[4] = {&m.pan_rad, &m.tilt_rad, &m.pan_rate_radps, &m.tilt_rate_radps};
  for (int i = 0; i < 4; ++i) {
    const SignalSpec& s = specs[static_cast<std::size_t>(kPan + i)];
    const std::int64_t raw = raw_of(w, s);
    *values[i] = static_cast<double>(raw) * s.factor + s.offset;
    if (at_limit(raw, s)) m.saturated |= static_cast<HeadJointMask>(1u << i);
  }
  return m;
}
}  // namespace

std::string_view to_string(HeadMode mode) {
  switch (mode) {
    case HeadMode::Off: return "off";
    case HeadMode::Position: return "position";
    case HeadMode::Rate: return "rate";
    case HeadMode::SafeStop: return "safe_stop";
  }
  return "?";
}

std::expected<EncodedFrame, WireError> encode(const HeadCommand& m) {
  return encode_joints(m, kIdHeadCommand, MessageType::HeadCommand);
}
std::expected<EncodedFrame, WireError> encode(const HeadState& m) {
  return encode_joints(m, kIdHeadState, MessageType::HeadState);
}
std::expected<HeadCommand, WireError> decode_head_command(const CanFrame& frame) {
  return decode_joints<HeadCommand>(frame, kIdHeadCommand, MessageType::HeadCommand);
}
std::expected<HeadState, WireError> decode_head_state(const CanFrame& frame) {
  return decode_joints<HeadState>(frame, kIdHeadState, MessageType::HeadState);
}

}  // namespace epichead::firmware_iface
