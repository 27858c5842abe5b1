#pragma once
// How the replay reports write CAN ids and numbers: one spelling for every table and message.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

namespace epichead::tools::replay {

// As candump writes them: 3 hex digits for an 11-bit id, 8 for a 29-bit one.
inline std::string hex_id(std::uint32_t id, bool extended) {
  char buf[16];
  std::snprintf(buf, sizeof buf, extended ? "0x%08X" : "0x%03X", id);
  return buf;
}

// A number in a printf format; "-" when it is not finite (no figure rather than "nan").
inline std::string format_number(double v, const char* format) {
  if (!std::isfinite(v)) return "-";
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

}  // namespace epichead::tools::replay
