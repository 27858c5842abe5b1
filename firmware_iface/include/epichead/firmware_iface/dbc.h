#pragma once
// A CAN database (Vector DBC file) as data: the messages and their signals, so that frames of
// devices that are not ours (a battery, a motor controller on the robot's bus) can be decoded.
//
// Grammar read (the rest of the format is skipped):
//   BO_ <id> <name>: <length in bytes> <sender>
//    SG_ <name> [M | m<n>] : <start>|<length>@<0|1><+|-> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
//   VAL_ <id> <signal> <value> "<text>" ... ;
//   SIG_VALTYPE_ <id> <signal> : <1 = IEEE float | 2 = double> ;
//   BA_DEF_DEF_ "GenMsgCycleTime" <ms> ;     BA_ "GenMsgCycleTime" BO_ <id> <ms> ;
// Ids: bit 31 of the BO_ id marks a 29-bit id; an id over 0x7FF without it is taken as 29-bit
// too (databases written for J1939 often leave the flag out). Byte order @1 is Intel (little
// endian, start = least significant bit), @0 Motorola (big endian, start = most significant
// bit, in the sawtooth numbering: bit b is bit b % 8 of byte b / 8). Multiplexing: one plain
// multiplexor (M) per message; a signal m<n> is in a frame whose multiplexor reads n. Frames
// up to 64 bytes (CAN FD). Skipped: NS_, BS_, BU_, CM_, BA_DEF_, other BA_ attributes, EV_,
// VAL_TABLE_, SIG_GROUP_, BO_TX_BU_, and any section not named here; the pseudo message
// VECTOR__INDEPENDENT_SIG_MSG (signals not placed in a frame).
#include <cstdint>
#include <expected>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace epichead::firmware_iface {

enum class ByteOrder : std::uint8_t { Intel, Motorola };

// How the raw bits are read: an integer (signed or not), or an IEEE 754 value (SIG_VALTYPE_).
enum class SignalValueType : std::uint8_t { Integer, Float32, Float64 };

// Whether a signal is in every frame of its message, selects the others, or is in some only.
enum class Multiplexing : std::uint8_t { None, Multiplexor, Multiplexed };

struct DbcSignal {
  std::string name;
  int start_bit = 0;  // as written: the LSB (Intel) or the MSB (Motorola) in the sawtooth numbering
  int length = 1;     // bits, 1..64
  ByteOrder byte_order = ByteOrder::Intel;
  bool is_signed = false;
  SignalValueType value_type = SignalValueType::Integer;
  double factor = 1, offset = 0;  // physical = raw * factor + offset
  double min = 0, max = 0;        // the stated physical range; 0|0 states none
  std::string unit;
  Multiplexing multiplexing = Multiplexing::None;
  std::uint64_t multiplexer_value = 0;           // Multiplexed: the multiplexor's raw value that selects it
  std::map<std::int64_t, std::string> values;    // VAL_: raw value -> text
  int line = 0;                                  // where it is defined (1-based)

  bool has_range() const { return min != 0 || max != 0; }
};

struct DbcMessage {
  std::uint32_t id = 0;  // 11 or 29 bits, without the DBC's bit 31
  bool extended = false;
  std::string name;
  int length = 8;        // bytes, 0..64
  std::string sender;
  std::vector<DbcSignal> signals;
  int multiplexor = -1;  // index in signals of the multiplexor, -1 when none
  std::optional<int> cycle_time_ms;  // GenMsgCycleTime (BA_ or its BA_DEF_DEF_) when > 0: sent periodically
  int line = 0;

  const DbcSignal* signal(std::string_view name) const;
};

struct Dbc {
  std::string path;  // or the name given to parse_dbc
  std::vector<DbcMessage> messages;
  // "path:line: what" for what is read but cannot always be decoded: a signal beyond its
  // message's length (decoded only from frames long enough). The first 100.
  std::vector<std::string> warnings;

  // The message with this id, nullptr when the database has none.
  const DbcMessage* find(std::uint32_t id, bool extended) const;
  const DbcMessage* find(std::string_view name) const;
};

// Reads a DBC file. The error is one line, "path:line: what is wrong" (or "path: cannot
// open (...)"); any input gives a database or an error, never a crash or a hang.
std::expected<Dbc, std::string> load_dbc(const std::string& path);
// The same from text in memory; `name` stands for the path in errors.
std::expected<Dbc, std::string> parse_dbc(std::string_view text, const std::string& name);

// The frame length in bytes that holds all of the signal's bits (more than 64 for a signal no
// frame can hold: the reader rejects those; more than the message's length gives a warning).
int bytes_needed(const DbcSignal& signal);

}  // namespace epichead::firmware_iface
