#pragma once
// Private helpers shared by the message codecs: the 8 payload bytes as one little-endian
// 64-bit word, signals read and written through their SignalSpec, frame-shape checks.
#include <cmath>
#include <cstdint>
#include <expected>
#include <optional>
#include <span>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/encoded_frame.h"
#include "epichead/firmware_iface/fixed_point.h"
#include "epichead/firmware_iface/signal_table.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface::detail {

inline std::uint64_t load_word(const CanFrame& f) {
  std::uint64_t w = 0;
  for (int i = 7; i >= 0; --i) w = (w << 8) | f.data[static_cast<std::size_t>(i)];
  return w;
}

inline std::uint64_t field_mask(int length) { return length >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << length) - 1; }

inline std::int64_t raw_of(std::uint64_t word, const SignalSpec& s) {
  const std::uint64_t v = (word >> s.start_bit) & field_mask(s.length);
  if (!s.is_signed) return static_cast<std::int64_t>(v);
  const std::uint64_t sign = std::uint64_t{1} << (s.length - 1);
  return static_cast<std::int64_t>((v ^ sign) - sign);
}

inline double physical(std::uint64_t word, const SignalSpec& s) {
  return static_cast<double>(raw_of(word, s)) * s.factor + s.offset;
}

// A signed raw value at either end of its field: the sender's value was saturated.
inline bool at_limit(std::int64_t raw, const SignalSpec& s) {
  return s.is_signed && (raw == signed_min(s.length) || raw == signed_max(s.length));
}

// A classic 8-byte data frame with this id, or the reason it is not.
inline std::optional<WireError> check_shape(const CanFrame& f) {
  if (f.remote() || f.error() || f.extended() || f.fd())
    return WireError{WireErrorKind::NotClassicData, f.id, -1, {}, 0};
  if (f.len < kFrameLength) return WireError{WireErrorKind::ShortFrame, f.id, f.len, {}, f.len};
  if (f.len > kFrameLength) return WireError{WireErrorKind::LongFrame, f.id, kFrameLength, {}, f.len};
  return std::nullopt;
}

// The payload word of a classic 8-byte data frame with exactly this id, or why the frame is not one.
inline std::expected<std::uint64_t, WireError> payload_of(const CanFrame& f, std::uint32_t id) {
  if (f.id != id) return std::unexpected(WireError{WireErrorKind::UnknownId, f.id, -1, {}, 0});
  if (auto bad = check_shape(f)) return std::unexpected(*bad);
  return load_word(f);
}

// The same for a message whose CAN id carries a node number (heartbeat, time sync): the id's
// type and node, and the payload word.
struct NodePayload {
  MessageId id;
  std::uint64_t word = 0;
};
inline std::expected<NodePayload, WireError> node_payload_of(const CanFrame& f, MessageType type) {
  const auto id = classify_id(f.id);
  if (!id || id->type != type) return std::unexpected(WireError{WireErrorKind::UnknownId, f.id, -1, {}, 0});
  if (auto bad = check_shape(f)) return std::unexpected(*bad);
  return NodePayload{*id, load_word(f)};
}

inline WireError out_of_range(std::uint32_t id, const SignalSpec& s, std::int64_t raw) {
  return WireError{WireErrorKind::OutOfRange, id, s.start_bit / 8, s.name, raw};
}

// Builds a frame signal by signal, clipping and recording what did not fit.
class Packer {
 public:
  Packer(std::uint32_t id, MessageType type) : id_(id), specs_(signal_table(type)) {}

  void raw(int i, std::uint64_t value) {
    const SignalSpec& s = specs_[static_cast<std::size_t>(i)];
    word_ |= (value & field_mask(s.length)) << s.start_bit;
  }
  // Scales an SI value into signal i; false (and the error kept) if it is not finite.
  bool value(int i, double v) {
    const SignalSpec& s = specs_[static_cast<std::size_t>(i)];
    if (!std::isfinite(v)) {
      if (!error_) error_ = WireError{WireErrorKind::NotFinite, id_, s.start_bit / 8, s.name, 0};
      return false;
    }
    const std::int64_t lo = s.is_signed ? signed_min(s.length) : 0;
    const std::int64_t hi = s.is_signed ? signed_max(s.length) : unsigned_max(s.length);
    const Quantized q = quantize(v - s.offset, s.factor, lo, hi);
    if (q.clipped) clipped_ |= 1u << i;
    raw(i, static_cast<std::uint64_t>(q.raw));
    return true;
  }
  std::expected<EncodedFrame, WireError> finish() const {
    if (error_) return std::unexpected(*error_);
    EncodedFrame out;
    out.frame.id = id_;
    out.frame.len = kFrameLength;
    for (int b = 0; b < 8; ++b) out.frame.data[static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(word_ >> (8 * b));
    out.clipped = clipped_;
    return out;
  }

 private:
  std::uint32_t id_;
  std::span<const SignalSpec> specs_;
  std::uint64_t word_ = 0;
  std::uint32_t clipped_ = 0;
  std::optional<WireError> error_;
};

}  // namespace epichead::firmware_iface::detail
