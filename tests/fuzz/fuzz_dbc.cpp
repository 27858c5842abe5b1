// The DBC reader (dbc.h) and the signal decoder (dbc_decode.h). The input is a DBC text, then
// optionally a line "@@frame@@" and bytes decoded as a frame of every message. Properties: a
// database or a one-line error naming the input and a line within it, never a crash or a hang;
// a database's messages have lengths 0..64, unique ids, ids within 29 bits (11 when not
// extended), signals of 1..64 bits inside 64 bytes, finite factors and ranges, a multiplexor
// for every multiplexed signal; units and value texts are well-formed UTF-8 (the JSON report
// takes them); the same text from a file reads the same; decoding reads no
// byte past the frame, and bits written with insert_bits read back.
#include <nlohmann/json.hpp>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "epichead/firmware_iface/dbc.h"
#include "epichead/firmware_iface/dbc_decode.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

namespace {

// The replay report writes units into JSON, whose writer throws on text that is not UTF-8.
bool json_safe(const std::string& text) {
  try {
    (void)nlohmann::json(text).dump();
    return true;
  } catch (const nlohmann::json::exception&) {
    return false;
  }
}

void check_database(const Dbc& d, std::size_t lines) {
  std::set<std::uint64_t> ids;
  for (const DbcMessage& m : d.messages) {
    check(m.length >= 0 && m.length <= 64, "message length outside 0..64");
    check(m.id <= (m.extended ? 0x1FFFFFFFu : 0x7FFu), "id wider than its format");
    check(ids.insert(m.id | (std::uint64_t{m.extended} << 32)).second, "two messages with one id");
    check(m.line >= 1 && static_cast<std::size_t>(m.line) <= lines, "message line outside the input");
    check(!m.cycle_time_ms || *m.cycle_time_ms > 0, "a cycle time of 0 or less kept");
    bool multiplexed = false;
    for (const DbcSignal& s : m.signals) {
      check(s.length >= 1 && s.length <= 64, "signal length outside 1..64");
      check(bytes_needed(s) <= 64, "signal beyond 64 bytes");
      check(std::isfinite(s.factor) && std::isfinite(s.offset) && std::isfinite(s.min) && std::isfinite(s.max),
            "a signal's scale or range is not finite");
      check(s.value_type == SignalValueType::Integer || s.length == (s.value_type == SignalValueType::Float32 ? 32 : 64),
            "a float signal of the wrong width");
      multiplexed |= s.multiplexing == Multiplexing::Multiplexed;
      for (const auto& [raw, text] : s.values) {
        epichead::fuzz::check_one_line(text.empty() ? "x" : text, "value text");
        check(json_safe(text), "a value text is not well-formed UTF-8");
      }
      check(s.unit.find('\n') == std::string::npos, "a unit spans lines");
      check(json_safe(s.unit), "a unit is not well-formed UTF-8 (the JSON report would throw)");
    }
    check(!multiplexed || (m.multiplexor >= 0 && static_cast<std::size_t>(m.multiplexor) < m.signals.size()),
          "multiplexed signals without a multiplexor");
  }
  for (const auto& w : d.warnings) epichead::fuzz::check_one_line(w, "DBC warning");
}

void check_decoding(const Dbc& d, std::string_view frame_bytes) {
  // The frame as its own allocation of exactly its length, so that ASan sees a read past it.
  std::vector<std::uint8_t> data(frame_bytes.begin(), frame_bytes.begin() + std::min<std::size_t>(frame_bytes.size(), 64));
  for (const DbcMessage& m : d.messages) {
    std::vector<DbcValue> out(m.signals.size());
    const DbcFrameDecode r = decode_frame(m, data, out);
    check(r.values + r.too_short <= m.signals.size(), "more values than signals");
    for (std::size_t i = 0; i < r.values; ++i) {
      const DbcSignal& s = m.signals[out[i].signal];
      check(s.length == 64 || out[i].bits >> s.length == 0, "bits beyond the signal's length");
      std::vector<std::uint8_t> copy(data.size());
      check(insert_bits(s, out[i].bits, copy), "insert_bits refused a signal extract_bits read");
      check(extract_bits(s, copy) == out[i].bits, "insert_bits then extract_bits changed the value");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto parts = epichead::fuzz::split(epichead::fuzz::as_text(data, size), "\n@@frame@@\n");
  const std::string text(parts[0]);
  std::size_t lines = 1;
  for (char c : text) lines += c == '\n';
  const auto memory = parse_dbc(text, "fuzz.dbc");
  if (!memory) {
    epichead::fuzz::check_one_line(memory.error(), "DBC error");
    check(memory.error().rfind("fuzz.dbc:", 0) == 0, "the error does not name the input: " + memory.error());
    const std::size_t colon = memory.error().find(':', 9);
    const std::string line = memory.error().substr(9, colon == std::string::npos ? 0 : colon - 9);
    check(!line.empty() && line.find_first_not_of("0123456789") == std::string::npos && std::stoull(line) >= 1 &&
              std::stoull(line) <= lines,
          "the error names no line within the input: " + memory.error());
  } else {
    check_database(*memory, lines);
    for (std::size_t i = 1; i < parts.size(); ++i) check_decoding(*memory, parts[i]);
  }
  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  const auto file = load_dbc(scratch.write("fuzz.dbc", text));
  check(file.has_value() == memory.has_value(), "file and memory readers disagree");
  if (file && memory) check(file->messages.size() == memory->messages.size(), "file and memory readers disagree on messages");
  return 0;
}
