#include "epichead/firmware_iface/dbc_decode.h"

#include <bit>
#include <cstring>

namespace epichead::firmware_iface {

namespace {

// The frame bit (Intel numbering: bit b is bit b % 8 of byte b / 8) that holds bit i of the
// field, i = 0 being the least significant. Intel fields run up from the start bit; Motorola
// fields run from the most significant bit at the start bit down each byte, then on to the
// next byte's bit 7 (the DBC's sawtooth numbering).
int frame_bit(const DbcSignal& s, int i) {
  if (s.byte_order == ByteOrder::Intel) return s.start_bit + i;
  const int from_msb = s.length - 1 - i;  // steps from the start bit towards the LSB
  const int in_first = s.start_bit % 8 + 1;  // bits of the first byte at and below the start bit
  if (from_msb < in_first) return s.start_bit - from_msb;
  const int rest = from_msb - in_first;  // into the following bytes, from their bit 7
  return (s.start_bit / 8 + 1 + rest / 8) * 8 + 7 - rest % 8;
}

std::uint64_t low_bits(std::uint64_t v, int length) { return length >= 64 ? v : v & ((std::uint64_t{1} << length) - 1); }

}  // namespace

int bytes_needed(const DbcSignal& s) {
  // The highest frame bit is the MSB for Intel and the LSB for Motorola.
  const int top = frame_bit(s, s.byte_order == ByteOrder::Intel ? s.length - 1 : 0);
  return top / 8 + 1;
}

std::optional<std::uint64_t> extract_bits(const DbcSignal& s, std::span<const std::uint8_t> data) {
  if (s.length < 1 || s.length > 64 || s.start_bit < 0) return std::nullopt;
  if (static_cast<std::size_t>(bytes_needed(s)) > data.size()) return std::nullopt;
  std::uint64_t v = 0;
  for (int i = 0; i < s.length; ++i) {
    const int b = frame_bit(s, i);
    v |= static_cast<std::uint64_t>((data[static_cast<std::size_t>(b / 8)] >> (b % 8)) & 1u) << i;
  }
  return v;
}

bool insert_bits(const DbcSignal& s, std::uint64_t bits, std::span<std::uint8_t> data) {
  if (s.length < 1 || s.length > 64 || s.start_bit < 0) return false;
  if (static_cast<std::size_t>(bytes_needed(s)) > data.size()) return false;
  for (int i = 0; i < s.length; ++i) {
    const int b = frame_bit(s, i);
    auto& byte = data[static_cast<std::size_t>(b / 8)];
    const auto mask = static_cast<std::uint8_t>(1u << (b % 8));
    byte = static_cast<std::uint8_t>(((bits >> i) & 1u) ? (byte | mask) : (byte & ~mask));
  }
  return true;
}

std::int64_t DbcValue::raw_signed(const DbcSignal& s) const {
  if (s.value_type != SignalValueType::Integer) return 0;
  if (!s.is_signed || s.length >= 64) return static_cast<std::int64_t>(bits);
  const std::uint64_t sign = std::uint64_t{1} << (s.length - 1);
  return static_cast<std::int64_t>((bits ^ sign) - sign);  // sign extension without shifts of negatives
}

DbcValue decode_bits(const DbcSignal& s, std::uint64_t bits) {
  DbcValue v;
  v.bits = low_bits(bits, s.length);
  switch (s.value_type) {
    case SignalValueType::Float32:
      v.raw = std::bit_cast<float>(static_cast<std::uint32_t>(v.bits));
      break;
    case SignalValueType::Float64:
      v.raw = std::bit_cast<double>(v.bits);
      break;
    case SignalValueType::Integer:
      v.raw = s.is_signed ? static_cast<double>(v.raw_signed(s)) : static_cast<double>(v.bits);
      break;
  }
  v.physical = v.raw * s.factor + s.offset;
  return v;
}

DbcFrameDecode decode_frame(const DbcMessage& m, std::span<const std::uint8_t> data, std::span<DbcValue> out) {
  DbcFrameDecode r;
  if (m.multiplexor >= 0 && static_cast<std::size_t>(m.multiplexor) < m.signals.size())
    r.multiplexer = extract_bits(m.signals[static_cast<std::size_t>(m.multiplexor)], data);
  for (std::size_t i = 0; i < m.signals.size() && r.values < out.size(); ++i) {
    const DbcSignal& s = m.signals[i];
    if (s.multiplexing == Multiplexing::Multiplexed && (!r.multiplexer || *r.multiplexer != s.multiplexer_value))
      continue;  // another multiplexed frame (or no multiplexor value to tell)
    const auto bits = extract_bits(s, data);
    if (!bits) {
      ++r.too_short;
      continue;
    }
    DbcValue v = decode_bits(s, *bits);
    v.signal = i;
    out[r.values++] = v;
  }
  return r;
}

std::string_view value_text(const DbcSignal& s, std::int64_t raw) {
  const auto it = s.values.find(raw);
  return it == s.values.end() ? std::string_view{} : std::string_view(it->second);
}

}  // namespace epichead::firmware_iface
