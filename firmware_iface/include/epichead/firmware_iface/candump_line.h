#pragma once
// One line of a can-utils candump log, parsed or formatted without allocation.
//
// Log format (candump -l, what canplayer reads and what we write):
//   (1436509052.249713) can0 123#DEADBEEF         classic, 11-bit id (3 hex digits)
//   (1436509052.249713) can0 1F334455#00          29-bit id (8 hex digits)
//   (1436509052.249713) can0 123#R  / 123#R4      remote frame, optional length digit
//   (1436509052.249713) can0 20000004#0004000000000000   error frame (id has the error flag 0x20000000)
//   (1436509052.249713) can0 123##1DEADBEEF       CAN FD: flags nibble (1 = BRS, 2 = ESI), data
//   ... 123#11.22.33         dots between bytes are allowed; "_X" after 8 bytes (raw DLC) too
//   ... 123#DEADBEEF R       a trailing direction (R = received, T = transmitted)
// Default (human-readable) candump output is read too, with or without a "(stamp)" prefix:
//   "  can0  680   [8]  03 22 01 00 00 00 00 00", "  can0  123   [2]  remote request"
// Blank lines and lines starting with '#' are skipped; a trailing '\r' (CRLF) is ignored.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "epichead/firmware_iface/can_frame.h"

namespace epichead::firmware_iface {

enum class CanDirection : std::uint8_t { Unknown, Received, Transmitted };

struct CandumpRecord {
  StampedCanFrame frame;       // stamp_us: the "(sec.usec)" time, 0 when the line has none
  bool has_stamp = false;
  std::string_view iface;      // points into the line (valid as long as the line is)
  CanDirection direction = CanDirection::Unknown;
};

enum class CandumpLineKind : std::uint8_t { Frame, Skip /* blank or comment */, Malformed };

struct CandumpParse {
  CandumpLineKind kind = CandumpLineKind::Malformed;
  const char* reason = "";  // for Malformed: what is wrong (a string literal)
  int column = 0;           // for Malformed: 1-based column where parsing stopped
};

// Parses one line (without its '\n'). On Frame, `out` holds the record.
CandumpParse parse_candump_line(std::string_view line, CandumpRecord& out);

// The longest interface name Linux allows (IFNAMSIZ - 1); format_candump_line cuts longer ones.
inline constexpr std::size_t kCandumpMaxIface = 15;

// Why `iface` cannot be a log line's interface field (empty, a blank in it, longer than
// kCandumpMaxIface), or nullptr when it can.
const char* candump_iface_problem(std::string_view iface);

namespace candump_detail {
// Characters of "(sec.usec) " for the stamp with the longest seconds, negative included.
constexpr std::size_t longest_stamp() {
  constexpr std::int64_t kMinUs = INT64_MIN;
  std::int64_t sec = kMinUs / 1'000'000 - 1;  // floor division, as format_candump_line does
  std::size_t digits = 0;
  for (; sec != 0; sec /= 10) ++digits;
  return 1 + 1 + (digits < 10 ? 10 : digits) + 1 + 6 + 1 + 1;  // '(' '-' sec '.' usec ')' ' '
}
}  // namespace candump_detail

// The longest line format_candump_line writes, with its '\n': the longest stamp, the longest
// interface name and a space, a 29-bit id, "##", the FD flags digit, 64 data bytes in hex,
// then " R" / " T" and the newline.
inline constexpr std::size_t kCandumpMaxLine =
    candump_detail::longest_stamp() + kCandumpMaxIface + 1 + 8 + 2 + 1 + 2 * kCanFdMaxData + 2 + 1;

// Formats a frame in the log format (with '\n') into buf (kCandumpMaxLine bytes at least);
// returns the length. A Direction other than Unknown is appended as " R" / " T". The frame
// should be possible (impossible_frame_reason: CandumpWriter checks): an impossible one is
// written as best it can be and does not read back the same.
std::size_t format_candump_line(const StampedCanFrame& frame, std::string_view iface, char* buf,
                                CanDirection direction = CanDirection::Unknown);

}  // namespace epichead::firmware_iface
