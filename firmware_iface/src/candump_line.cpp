#include "epichead/firmware_iface/candump_line.h"

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace epichead::firmware_iface {
namespace {

constexpr std::uint32_t kErrFlag = 0x20000000u;  // Linux CAN_ERR_FLAG as candump prints it
constexpr std::uint32_t kEffMask = 0x1FFFFFFFu;

// Hex digit value, or -1. A table keeps the data loop branch-light (2M frames/s budget).
struct HexTable {
  signed char v[256];
  constexpr HexTable() : v{} {
    for (int i = 0; i < 256; ++i) v[i] = -1;
    for (int i = 0; i < 10; ++i) v['0' + i] = static_cast<signed char>(i);
    for (int i = 0; i < 6; ++i) {
      v['A' + i] = static_cast<signed char>(10 + i);
      v['a' + i] = static_cast<signed char>(10 + i);
    }
  }
};
constexpr HexTable kHex;
inline int hex(char c) { return kHex.v[static_cast<unsigned char>(c)]; }

bool is_space(char c) { return c == ' ' || c == '\t'; }

struct Cursor {
  const char* begin;
  const char* p;
  const char* end;
  bool done() const { return p >= end; }
  char peek() const { return p < end ? *p : '\0'; }
  void skip_spaces() {
    while (p < end && is_space(*p)) ++p;
  }
  int column() const { return static_cast<int>(p - begin) + 1; }
};

CandumpParse bad(const Cursor& c, const char* reason) { return {CandumpLineKind::Malformed, reason, c.column()}; }

// "(sec.frac)" -> microseconds. Fraction digits beyond 6 are truncated; fewer are scaled.
bool parse_stamp(Cursor& c, std::int64_t& us) {
  ++c.p;  // '('
  std::int64_t sec = 0;
  int digits = 0;
  while (c.p < c.end && *c.p >= '0' && *c.p <= '9') {
    if (++digits > 12) return false;
    sec = sec * 10 + (*c.p++ - '0');
  }
  if (digits == 0 || c.peek() != '.') return false;
  ++c.p;
  std::int64_t frac = 0;
  int fdigits = 0;
  while (c.p < c.end && *c.p >= '0' && *c.p <= '9') {
    if (fdigits < 6) frac = frac * 10 + (*c.p - '0');
    ++fdigits;
    ++c.p;
  }
  if (fdigits == 0 || fdigits > 9 || c.peek() != ')') return false;
  for (int i = fdigits; i < 6; ++i) frac *= 10;
  ++c.p;
  us = sec * 1'000'000 + frac;
  return true;
}

// Hex id of 3 (11-bit) or 8 (29-bit) digits ending at a non-hex character.
bool parse_id(Cursor& c, CanFrame& f, int& digits) {
  std::uint32_t id = 0;
  digits = 0;
  while (c.p < c.end && hex(*c.p) >= 0) {
    if (++digits > 8) return false;
    id = (id << 4) | static_cast<std::uint32_t>(hex(*c.p++));
  }
  if (digits == 3) {
    if (id > 0x7FF) return false;
    f.id = id;
    f.flags = CanFlags::None;
    return true;
  }
  if (digits == 8) {
    if (id & kErrFlag) {
      f.id = id & kEffMask & ~kErrFlag;
      f.flags = CanFlags::Error;
    } else {
      f.id = id & kEffMask;
      f.flags = CanFlags::Extended;
    }
    return true;
  }
  return false;
}

bool valid_fd_length(int n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

CandumpParse parse_log_frame(Cursor& c, CandumpRecord& out) {
  CanFrame& f = out.frame.frame;
  int id_digits = 0;
  const char* id_start = c.p;
  if (!parse_id(c, f, id_digits)) {
    c.p = id_start;
    return bad(c, "CAN id must be 3 (11-bit) or 8 (29-bit) hex digits");
  }
  if (c.peek() != '#') return bad(c, "expected '#' after the CAN id");
  ++c.p;
  int max_len = kCanMaxData;
  if (c.peek() == '#') {  // CAN FD: flags nibble then data
    ++c.p;
    const int flags = c.done() ? -1 : hex(*c.p);
    if (flags < 0) return bad(c, "CAN FD frame needs a flags hex digit after '##'");
    ++c.p;
    f.flags = f.flags | CanFlags::Fd;
    if (flags & 1) f.flags = f.flags | CanFlags::BitRateSwitch;
    if (flags & 2) f.flags = f.flags | CanFlags::ErrorStateIndicator;
    max_len = kCanFdMaxData;
  } else if (c.peek() == 'R' || c.peek() == 'r') {
    if (f.error()) return bad(c, "an error frame cannot be a remote frame");
    ++c.p;
    f.flags = f.flags | CanFlags::Remote;
    f.len = 0;
    if (!c.done() && *c.p >= '0' && *c.p <= '8') f.len = static_cast<std::uint8_t>(*c.p++ - '0');
    if (c.peek() == '_') {  // raw DLC 9..F after a length of 8
      if (f.len != 8 || c.p + 1 >= c.end || hex(c.p[1]) < 9)
        return bad(c, "'_' raw DLC needs a length of 8 and a DLC 9..F");
      c.p += 2;
    }
    return {CandumpLineKind::Frame, "", 0};
  }
  int n = 0;
  while (c.p < c.end) {
    const char ch = *c.p;
    if (ch == '.') {
      ++c.p;
      continue;
    }
    const int hi = hex(ch);
    if (hi < 0) break;
    if (c.p + 1 >= c.end) return bad(c, "odd number of hex digits in data");
    const int lo = hex(c.p[1]);
    if (lo < 0) {
      ++c.p;
      return bad(c, "odd number of hex digits in data");
    }
    if (n >= max_len) return bad(c, max_len == kCanMaxData ? "more than 8 data bytes in a classic frame"
                                                           : "more than 64 data bytes in a CAN FD frame");
    f.data[static_cast<std::size_t>(n++)] = static_cast<std::uint8_t>((hi << 4) | lo);
    c.p += 2;
  }
  if (c.peek() == '_' && !f.fd()) {  // len8_dlc: "_X" after exactly 8 bytes
    if (n != 8 || c.p + 1 >= c.end || hex(c.p[1]) < 9) return bad(c, "'_' raw DLC needs 8 data bytes and a DLC 9..F");
    c.p += 2;
  }
  if (f.fd() && !valid_fd_length(n)) return bad(c, "CAN FD data length is not one of 0..8, 12, 16, 20, 24, 32, 48, 64");
  f.len = static_cast<std::uint8_t>(n);
  if (!c.done() && !is_space(*c.p)) return bad(c, "bad hex digit in data");
  return {CandumpLineKind::Frame, "", 0};
}

// "680   [8]  03 22 ..." (after the iface) of candump's default output.
CandumpParse parse_default_frame(Cursor& c, CandumpRecord& out) {
  CanFrame& f = out.frame.frame;
  int id_digits = 0;
  if (!parse_id(c, f, id_digits)) return bad(c, "CAN id must be 3 (11-bit) or 8 (29-bit) hex digits");
  c.skip_spaces();
  if (c.peek() != '[') return bad(c, "expected '[len]' after the CAN id");
  ++c.p;
  int len = 0, digits = 0;
  while (c.p < c.end && *c.p >= '0' && *c.p <= '9' && digits < 3) {
    len = len * 10 + (*c.p++ - '0');
    ++digits;
  }
  if (digits == 0 || c.peek() != ']' || len > kCanFdMaxData) return bad(c, "bad '[len]'");
  ++c.p;
  // Two digits ("[08]") mean candump printed a CAN FD frame.
  if (digits == 2 || len > kCanMaxData) {
    if (!valid_fd_length(len)) return bad(c, "CAN FD data length is not a CAN FD size");
    f.flags = f.flags | CanFlags::Fd;
  }
  c.skip_spaces();
  const std::string_view rest(c.p, static_cast<std::size_t>(c.end - c.p));
  if (rest.starts_with("remote request")) {
    f.flags = f.flags | CanFlags::Remote;
    f.len = static_cast<std::uint8_t>(len);
    c.p += 14;
    return {CandumpLineKind::Frame, "", 0};
  }
  for (int i = 0; i < len; ++i) {
    c.skip_spaces();
    if (c.end - c.p < 2) return bad(c, "fewer data bytes than '[len]' says");
    const int hi = hex(c.p[0]), lo = hex(c.p[1]);
    if (hi < 0 || lo < 0) return bad(c, "bad hex digit in data");
    f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>((hi << 4) | lo);
    c.p += 2;
  }
  f.len = static_cast<std::uint8_t>(len);
  return {CandumpLineKind::Frame, "", 0};
}

}  // namespace

CandumpParse parse_candump_line(std::string_view line, CandumpRecord& out) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  Cursor c{line.data(), line.data(), line.data() + line.size()};
  c.skip_spaces();
  if (c.done() || *c.p == '#') return {CandumpLineKind::Skip, "", 0};

  out.frame = StampedCanFrame{};
  out.has_stamp = false;
  out.direction = CanDirection::Unknown;
  if (*c.p == '(') {
    if (!parse_stamp(c, out.frame.stamp_us)) return bad(c, "bad timestamp, expected (seconds.microseconds)");
    out.has_stamp = true;
    c.skip_spaces();
  }
  const char* iface = c.p;
  while (c.p < c.end && !is_space(*c.p)) ++c.p;
  if (c.p == iface) return bad(c, "missing interface name");
  out.iface = std::string_view(iface, static_cast<std::size_t>(c.p - iface));
  if (c.done()) return bad(c, "missing frame after the interface name");
  c.skip_spaces();
  // Log format has "ID#..." right after one space; default output has the id, spaces, "[len]".
  const char* frame_start = c.p;
  while (c.p < c.end && hex(*c.p) >= 0) ++c.p;
  const bool log_form = c.peek() == '#';
  c.p = frame_start;
  const CandumpParse r = log_form ? parse_log_frame(c, out) : parse_default_frame(c, out);
  if (r.kind != CandumpLineKind::Frame) return r;
  if (const char* why = impossible_frame_reason(out.frame.frame)) {
    c.p = frame_start;
    return bad(c, why);
  }
  c.skip_spaces();
  if (!c.done() && log_form) {
    if (*c.p == 'R') out.direction = CanDirection::Received;
    else if (*c.p == 'T') out.direction = CanDirection::Transmitted;
    else return bad(c, "unexpected text after the frame (only a direction R or T may follow)");
    ++c.p;
    c.skip_spaces();
  }
  if (!c.done()) return bad(c, "unexpected text after the frame");
  return r;
}

std::size_t format_candump_line(const StampedCanFrame& s, std::string_view iface, char* buf, CanDirection direction) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  char* p = buf;
  // Floor division so that a negative stamp still prints a fraction in 0..999999.
  std::int64_t sec = s.stamp_us / 1'000'000, usec = s.stamp_us % 1'000'000;
  if (usec < 0) {
    usec += 1'000'000;
    --sec;
  }
  p += std::snprintf(p, 40, "(%010lld.%06lld) ", static_cast<long long>(sec), static_cast<long long>(usec));
  const std::size_t n_iface = std::min(iface.size(), kCandumpMaxIface);
  std::memcpy(p, iface.data(), n_iface);
  p += n_iface;
  *p++ = ' ';
  const CanFrame& f = s.frame;
  const auto put_hex = [&p](std::uint32_t v, int digits) {
    for (int i = digits - 1; i >= 0; --i) *p++ = kDigits[(v >> (4 * i)) & 0xF];
  };
  if (f.error())
    put_hex((f.id & kEffMask) | kErrFlag, 8);
  else if (f.extended())
    put_hex(f.id & kEffMask, 8);
  else
    put_hex(f.id & 0x7FF, 3);
  *p++ = '#';
  const int max_len = f.fd() ? kCanFdMaxData : kCanMaxData;
  const int len = f.len > max_len ? max_len : f.len;
  if (f.remote() && !f.fd()) {
    *p++ = 'R';
    if (len > 0) *p++ = static_cast<char>('0' + len);
  } else {
    if (f.fd()) {
      *p++ = '#';
      const int flags = has(f.flags, CanFlags::BitRateSwitch) ? 1 : 0;
      *p++ = kDigits[flags | (has(f.flags, CanFlags::ErrorStateIndicator) ? 2 : 0)];
    }
    for (int i = 0; i < len; ++i) put_hex(f.data[static_cast<std::size_t>(i)], 2);
  }
  if (direction != CanDirection::Unknown) {
    *p++ = ' ';
    *p++ = direction == CanDirection::Received ? 'R' : 'T';
  }
  *p++ = '\n';
  return static_cast<std::size_t>(p - buf);
}

const char* candump_iface_problem(std::string_view iface) {
  if (iface.empty()) return "is empty";
  if (iface.find_first_of(" \t\r\n") != std::string_view::npos) return "has blanks";
  static_assert(kCandumpMaxIface == 15, "the message below names the limit");
  if (iface.size() > kCandumpMaxIface) return "is longer than 15 characters";
  return nullptr;
}

}  // namespace epichead::firmware_iface
