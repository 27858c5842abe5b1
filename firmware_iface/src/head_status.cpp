#include "epichead/firmware_iface/head_status.h"

#include "frame_codec.h"

namespace epichead::firmware_iface {

using detail::at_limit;
using detail::Packer;
using detail::raw_of;

namespace {
constexpr int kPanCurrent = 0, kTiltCurrent = 1, kFaults = 2, kCounter = 3, kTemperature = 4;
}

std::string_view head_fault_name(int bit) {
  static constexpr std::string_view kNames[kHeadFaultBits] = {
      "pan_over_current", "tilt_over_current", "pan_limit", "tilt_limit", "over_temperature",
      "under_voltage",    "encoder",           "command_timeout", "bus_error"};
  return bit >= 0 && bit < kHeadFaultBits ? kNames[bit] : std::string_view{};
}

std::expected<EncodedFrame, WireError> encode(const HeadStatus& m) {
  const auto specs = signal_table(MessageType::HeadStatus);
  if (m.faults & ~kHeadFaultDefinedMask)
    return std::unexpected(detail::out_of_range(kIdHeadStatus, specs[kFaults], m.faults));
  Packer p(kIdHeadStatus, MessageType::HeadStatus);
  p.value(kPanCurrent, m.pan_current_a);
  p.value(kTiltCurrent, m.tilt_current_a);
  p.raw(kFaults, m.faults);
  p.raw(kCounter, m.counter);
  p.value(kTemperature, static_cast<double>(m.temperature_degc));
  return p.finish();
}

std::expected<HeadStatus, WireError> decode_head_status(const CanFrame& frame) {
  const auto payload = detail::payload_of(frame, kIdHeadStatus);
  if (!payload) return std::unexpected(payload.error());
  const std::uint64_t w = *payload;
  const auto specs = signal_table(MessageType::HeadStatus);
  const std::int64_t faults = raw_of(w, specs[kFaults]);
  if (faults & ~static_cast<std::int64_t>(kHeadFaultDefinedMask))
    return std::unexpected(detail::out_of_range(kIdHeadStatus, specs[kFaults], faults));
  HeadStatus m;
  const std::int64_t pan = raw_of(w, specs[kPanCurrent]);
  const std::int64_t tilt = raw_of(w, specs[kTiltCurrent]);
  const std::int64_t temp = raw_of(w, specs[kTemperature]);
  m.pan_current_a = static_cast<double>(pan) * specs[kPanCurrent].factor;
  m.tilt_current_a = static_cast<double>(tilt) * specs[kTiltCurrent].factor;
  m.faults = static_cast<std::uint16_t>(faults);
  m.counter = static_cast<std::uint8_t>(raw_of(w, specs[kCounter]));
  m.temperature_degc = static_cast<int>(temp);
  m.saturated = static_cast<std::uint8_t>((at_limit(pan, specs[kPanCurrent]) ? 1 : 0) |
                                          (at_limit(tilt, specs[kTiltCurrent]) ? 2 : 0) |
                                          (at_limit(temp, specs[kTemperature]) ? 4 : 0));
  return m;
}

}  // namespace epichead::firmware_iface
