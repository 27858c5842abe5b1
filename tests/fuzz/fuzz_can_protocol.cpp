// The CAN protocol codec (protocol.h): any frame through decode(). Properties: no crash; a
// decoded message encodes, without clipping, back into the very frame it came from (id,
// length, all eight bytes), and that frame decodes to the same message.
//
// Input: byte 0 = CanFlags bits, bytes 1-4 = id (little-endian; 11 bits unless Extended),
// byte 5 = length, then the data bytes.
#include <cstring>
#include <string>
#include <variant>

#include "epichead/firmware_iface/protocol.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

namespace {

CanFrame frame_from(const std::uint8_t* data, std::size_t size) {
  epichead::fuzz::ByteReader in(data, size);
  CanFrame f;
  f.flags = static_cast<CanFlags>(in.u8() & 0x3F);
  if (!f.fd()) f.flags = f.flags & (CanFlags::Extended | CanFlags::Remote | CanFlags::Error);  // BRS, ESI: FD only
  const std::uint32_t id = in.u32();
  f.id = f.extended() ? id & 0x1FFFFFFFu : id & 0x7FFu;
  f.len = static_cast<std::uint8_t>(in.u8() % (kCanFdMaxData + 1));
  for (std::size_t i = 0; i < f.len; ++i) f.data[i] = in.u8();
  return f;
}

std::string hex(const CanFrame& f) {
  static const char* digits = "0123456789ABCDEF";
  std::string s = std::to_string(f.id) + "#";
  for (int i = 0; i < f.len; ++i) {
    s += digits[f.data[static_cast<std::size_t>(i)] >> 4];
    s += digits[f.data[static_cast<std::size_t>(i)] & 15];
  }
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const CanFrame frame = frame_from(data, size);
  const auto message = decode(frame);
  if (!message) {
    epichead::fuzz::check_one_line(message.error().message(), "wire error");
    return 0;
  }
  const auto encoded = std::visit([](const auto& m) { return encode(m); }, *message);
  check(encoded.has_value(), "a decoded message does not encode: " + hex(frame) + ": " +
                                 (encoded ? std::string() : encoded.error().message()));
  const CanFrame& back = encoded->frame;
  check(encoded->clipped == 0, "a decoded message is clipped when encoded: " + hex(frame));
  check(back.id == frame.id && back.flags == frame.flags && back.len == frame.len &&
            std::memcmp(back.data.data(), frame.data.data(), frame.len) == 0,
        "decode -> encode changed the frame: " + hex(frame) + " -> " + hex(back));
  const auto again = decode(back);
  check(again.has_value() && again->index() == message->index(), "the re-encoded frame does not decode alike");
  return 0;
}
