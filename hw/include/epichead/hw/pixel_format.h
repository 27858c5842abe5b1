#pragma once
// Pixel formats a camera port delivers, with the FourCC codes V4L2 (and most capture APIs) use
// for them, so a format is named the same way in configuration, logs and drivers.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace epichead::hw {

enum class PixelFormat : std::uint8_t {
  Gray8,  // 'GREY': 8-bit luminance
  Yuyv,   // 'YUYV': 4:2:2, Y0 U Y1 V
  Rgb24,  // 'RGB3': R, G, B bytes
  Bgr24,  // 'BGR3': B, G, R bytes
  Mjpeg,  // 'MJPG': one JPEG per frame, size varies
  Other,  // anything else: see the frame's fourcc
};

constexpr std::uint32_t fourcc(char a, char b, char c, char d) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24;
}

PixelFormat pixel_format_from_fourcc(std::uint32_t code);
std::uint32_t fourcc_of(PixelFormat format);  // 0 for Other
// "YUYV"; unprintable bytes as '?'.
std::string fourcc_to_string(std::uint32_t code);
// "YUYV" -> code; nullopt unless exactly four printable characters.
std::optional<std::uint32_t> fourcc_from_string(std::string_view text);
// Bytes per pixel of an uncompressed format (0 for Mjpeg and Other).
int bytes_per_pixel(PixelFormat format);

}  // namespace epichead::hw
