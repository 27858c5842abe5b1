#include "printable.h"

#include <cstdint>
#include <cstdio>

namespace epichead::tools {
namespace {

void put_escape(std::string& out, const char* format, unsigned value) {
  char buf[8];
  std::snprintf(buf, sizeof buf, format, value);
  out += buf;
}

// Length of the valid UTF-8 sequence at text[i] (2..4) and its code point, or 0 when the
// bytes there are not one (stray continuation, overlong form, surrogate, beyond U+10FFFF).
int utf8_sequence(std::string_view text, std::size_t i, std::uint32_t& code_point) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char lead = byte(i);
  int n = 0;
  std::uint32_t min = 0;
  if (lead >= 0xC2 && lead <= 0xDF) n = 2, code_point = lead & 0x1F, min = 0x80;
  else if (lead >= 0xE0 && lead <= 0xEF) n = 3, code_point = lead & 0x0F, min = 0x800;
  else if (lead >= 0xF0 && lead <= 0xF4) n = 4, code_point = lead & 0x07, min = 0x10000;
  else return 0;
  if (i + static_cast<std::size_t>(n) > text.size()) return 0;
  for (int k = 1; k < n; ++k) {
    const unsigned char c = byte(i + static_cast<std::size_t>(k));
    if ((c & 0xC0) != 0x80) return 0;
    code_point = (code_point << 6) | (c & 0x3F);
  }
  if (code_point < min || code_point > 0x10FFFF || (code_point >= 0xD800 && code_point <= 0xDFFF)) return 0;
  return n;
}

}  // namespace

std::string printable(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if (c < 0x80) {
      if ((c < 0x20 && c != '\t') || c == 0x7F) put_escape(out, "\\x%02X", c);
      else out += static_cast<char>(c);
      ++i;
      continue;
    }
    std::uint32_t code_point = 0;
    const int n = utf8_sequence(text, i, code_point);
    if (n == 0) {
      put_escape(out, "\\x%02X", c);
      ++i;
    } else if (code_point < 0xA0) {  // C1 controls: some terminals act on them
      put_escape(out, "\\u%04X", code_point);
      i += static_cast<std::size_t>(n);
    } else {
      out.append(text.substr(i, static_cast<std::size_t>(n)));
      i += static_cast<std::size_t>(n);
    }
  }
  return out;
}

}  // namespace epichead::tools
