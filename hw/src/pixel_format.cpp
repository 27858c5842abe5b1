#include "epichead/hw/pixel_format.h"

namespace epichead::hw {

PixelFormat pixel_format_from_fourcc(std::uint32_t code) {
  for (PixelFormat f : {PixelFormat::Gray8, PixelFormat::Yuyv, PixelFormat::Rgb24, PixelFormat::Bgr24, PixelFormat::Mjpeg}) {
    if (fourcc_of(f) == code) return f;
  }
  return PixelFormat::Other;
}

std::uint32_t fourcc_of(PixelFormat format) {
  switch (format) {
    case PixelFormat::Gray8: return fourcc('G', 'R', 'E', 'Y');
    case PixelFormat::Yuyv: return fourcc('Y', 'U', 'Y', 'V');
    case PixelFormat::Rgb24: return fourcc('R', 'G', 'B', '3');
    case PixelFormat::Bgr24: return fourcc('B', 'G', 'R', '3');
    case PixelFormat::Mjpeg: return fourcc('M', 'J', 'P', 'G');
    case PixelFormat::Other: return 0;
  }
  return 0;
}

std::string fourcc_to_string(std::uint32_t code) {
  std::string text(4, '?');
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((code >> (8 * i)) & 0xFF);
    if (c >= 0x20 && c < 0x7F) text[i] = c;
  }
  return text;
}

std::optional<std::uint32_t> fourcc_from_string(std::string_view text) {
  if (text.size() != 4) return std::nullopt;
  for (char c : text) {
    if (c < 0x20 || c >= 0x7F) return std::nullopt;
  }
  return fourcc(text[0], text[1], text[2], text[3]);
}

int bytes_per_pixel(PixelFormat format) {
  switch (format) {
    case PixelFormat::Gray8: return 1;
    case PixelFormat::Yuyv: return 2;
    case PixelFormat::Rgb24:
    case PixelFormat::Bgr24: return 3;
    case PixelFormat::Mjpeg:
    case PixelFormat::Other: return 0;
  }
  return 0;
}

}  // namespace epichead::hw
