#pragma once
// Signals of a DBC message (dbc.h) read out of a frame's bytes, without allocation: the raw
// bits, the raw number (sign-extended, or the IEEE value of a float signal) and the physical
// value. Also the inverse for the bits, so tests can build frames from a database.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "epichead/firmware_iface/dbc.h"

namespace epichead::firmware_iface {

struct DbcValue {
  std::size_t signal = 0;  // index in DbcMessage::signals
  std::uint64_t bits = 0;  // the field as read, zero-extended
  double raw = 0;          // the integer (sign-extended when signed), or the float signal's value
  double physical = 0;     // raw * factor + offset

  // The integer raw value, exact for any width (bits sign-extended); 0 for float signals.
  std::int64_t raw_signed(const DbcSignal& s) const;
};

// The signal's bits from the frame's data; nullopt when the data is too short to hold them.
std::optional<std::uint64_t> extract_bits(const DbcSignal& signal, std::span<const std::uint8_t> data);
// Writes the low signal.length bits of `bits` into the signal's place; false (data untouched)
// when data is too short.
bool insert_bits(const DbcSignal& signal, std::uint64_t bits, std::span<std::uint8_t> data);
// Raw number and physical value of the signal's bits.
DbcValue decode_bits(const DbcSignal& signal, std::uint64_t bits);

struct DbcFrameDecode {
  std::size_t values = 0;     // entries written to `out`
  std::size_t too_short = 0;  // signals of this frame the data was too short for
  // The multiplexor's raw value (nullopt: no multiplexor, or the frame too short for it).
  std::optional<std::uint64_t> multiplexer;
};

// Decodes the signals of `message` that the frame carries: every plain signal, the
// multiplexor, and the multiplexed signals its value selects. `out` needs
// message.signals.size() entries (fewer: the rest are not decoded).
DbcFrameDecode decode_frame(const DbcMessage& message, std::span<const std::uint8_t> data, std::span<DbcValue> out);

// The VAL_ text of a raw value, empty when the signal has none for it.
std::string_view value_text(const DbcSignal& signal, std::int64_t raw);

}  // namespace epichead::firmware_iface
