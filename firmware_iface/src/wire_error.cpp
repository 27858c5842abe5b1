#include "epichead/firmware_iface/wire_error.h"

#include <cstdio>

namespace epichead::firmware_iface {

std::string_view to_string(WireErrorKind kind) {
  switch (kind) {
    case WireErrorKind::UnknownId: return "unknown id";
    case WireErrorKind::NotClassicData: return "not a classic data frame";
    case WireErrorKind::ShortFrame: return "short frame";
    case WireErrorKind::LongFrame: return "long frame";
    case WireErrorKind::OutOfRange: return "out of range";
    case WireErrorKind::NotFinite: return "not finite";
    case WireErrorKind::BadReportId: return "bad report id";
    case WireErrorKind::BadTransfer: return "bad transfer";
  }
  return "error";
}

std::string WireError::message() const {
  char buf[160];
  int n = std::snprintf(buf, sizeof buf, "CAN 0x%X", static_cast<unsigned>(id));
  if (kind == WireErrorKind::BadReportId) n = std::snprintf(buf, sizeof buf, "HID report 0x%02X", static_cast<unsigned>(id));
  std::string out(buf, static_cast<std::size_t>(n));
  if (byte >= 0) out += " byte " + std::to_string(byte);
  if (!field.empty()) out += " (" + std::string(field) + ")";
  out += ": ";
  out += to_string(kind);
  switch (kind) {
    case WireErrorKind::ShortFrame:
    case WireErrorKind::LongFrame: out += ", " + std::to_string(value) + " bytes"; break;
    case WireErrorKind::OutOfRange: out += ", raw value " + std::to_string(value); break;
    default: break;
  }
  return out;
}

}  // namespace epichead::firmware_iface
