#pragma once
// Head -> controller: motor currents, fault bits and driver temperature.
//
// HeadStatus 0x121, 8 bytes:
//   bytes 0-1   pan_current     int16, 1 mA/LSB (+-32.767 A)
//   bytes 2-3   tilt_current    int16, 1 mA/LSB
//   bytes 4-5   faults          uint16, HeadFault bits; bits 9-15 reserved (must be 0)
//   byte 6      counter         uint8, rolling
//   byte 7      temperature     int8, 1 degC/LSB (motor driver)
#include <cstdint>
#include <expected>
#include <string_view>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr double kMotorCurrentAPerLsb = 0.001;

// Fault bits of HeadStatus.faults.
enum HeadFault : std::uint16_t {
  kFaultPanOverCurrent = 1u << 0,
  kFaultTiltOverCurrent = 1u << 1,
  kFaultPanLimit = 1u << 2,       // end stop / soft limit reached
  kFaultTiltLimit = 1u << 3,
  kFaultOverTemperature = 1u << 4,
  kFaultUnderVoltage = 1u << 5,
  kFaultEncoder = 1u << 6,
  kFaultCommandTimeout = 1u << 7,  // no HeadCommand in time: head went to SafeStop
  kFaultBusError = 1u << 8,
};
inline constexpr int kHeadFaultBits = 9;
inline constexpr std::uint16_t kHeadFaultDefinedMask = (1u << kHeadFaultBits) - 1;

// "pan_over_current" etc. for bit 0..8; empty for others.
std::string_view head_fault_name(int bit);

struct HeadStatus {
  double pan_current_a = 0, tilt_current_a = 0;
  std::uint16_t faults = 0;
  std::uint8_t counter = 0;
  int temperature_degc = 0;
  std::uint8_t saturated = 0;  // decode only: bit 0 pan current, 1 tilt current, 2 temperature
};

std::expected<EncodedFrame, WireError> encode(const HeadStatus& m);
std::expected<HeadStatus, WireError> decode_head_status(const CanFrame& frame);

}  // namespace epichead::firmware_iface
