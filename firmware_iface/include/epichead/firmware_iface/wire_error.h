#pragma once
// Why a frame or report from the wire was rejected: a small value (no allocation on the
// decode path) that names the CAN id, the byte and the field; message() spells it out.
#include <cstdint>
#include <string>
#include <string_view>

namespace epichead::firmware_iface {

enum class WireErrorKind : std::uint8_t {
  UnknownId,       // not a frame of this protocol
  NotClassicData,  // remote, error, extended or FD frame where a classic data frame is expected
  ShortFrame,      // fewer bytes than the layout needs
  LongFrame,       // more bytes than the layout has
  OutOfRange,      // a field holds a value the layout does not define (enum, reserved bits)
  NotFinite,       // encode: a NaN or infinite value
  BadReportId,     // HID: first byte is not the expected report ID
  BadTransfer,     // DroneCAN: tail byte, toggle, CRC or payload length wrong
};

struct WireError {
  WireErrorKind kind = WireErrorKind::OutOfRange;
  std::uint32_t id = 0;        // CAN id (or HID report id)
  int byte = -1;               // first byte of the offending field, -1 when not one field
  std::string_view field{};    // signal name as in the DBC / docs (a string literal)
  std::int64_t value = 0;      // the offending raw value or length, when there is one

  // One line: "CAN 0x110 byte 6 (counter): short frame, 5 bytes".
  std::string message() const;
};

std::string_view to_string(WireErrorKind kind);

}  // namespace epichead::firmware_iface
