// The DBC reader (dbc.h). DBC is written by hand as often as by tools, and no Debian library
// reads it from C++, so this is a small reader of the part of the format that decoding needs.
// BO_ and SG_ are one line each; the other sections it reads (VAL_, SIG_VALTYPE_, BA_DEF_DEF_,
// BA_) end with ';' and may span lines, as CM_ comments do. Every loop consumes input, so any
// bytes end in a database or one error line.
#include "epichead/firmware_iface/dbc.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "epichead/firmware_iface/dbc_decode.h"

namespace epichead::firmware_iface {

namespace {

constexpr std::uint32_t kExtendedFlag = 0x8000'0000u;
constexpr std::uint32_t kIdMask = 0x1FFF'FFFFu;
constexpr std::uint32_t kMaxStandardId = 0x7FF;
constexpr int kMaxFrameBytes = 64;
constexpr std::size_t kKeptWarnings = 100;
constexpr std::string_view kCycleTime = "GenMsgCycleTime";

// Sections that end with ';' (and may span lines); the rest of the format is one line each.
constexpr std::array<std::string_view, 27> kStatementSections = {
    "CM_",        "BA_DEF_",      "BA_DEF_DEF_",    "BA_",          "VAL_",        "SIG_VALTYPE_",  "VAL_TABLE_",
    "EV_",        "ENVVAR_DATA_", "BO_TX_BU_",      "SG_MUL_VAL_",  "SIG_GROUP_",  "SGTYPE_",       "SGTYPE_VAL_",
    "SIG_TYPE_REF_", "BA_DEF_SGTYPE_", "BA_SGTYPE_", "BA_DEF_REL_", "BA_REL_",     "BA_DEF_DEF_REL_", "BU_SG_REL_",
    "BU_EV_REL_", "BU_BO_REL_",   "CAT_DEF_",       "CAT_",         "FILTER",      "SIGTYPE_VALTYPE_"};

bool is_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
}
bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

// What the input holds at a place, for an error message: up to 16 printable characters.
std::string shown(std::string_view rest) {
  std::string out;
  for (char c : rest) {
    if (is_space(c) || out.size() >= 16) break;
    out += (c >= 0x21 && c <= 0x7E) ? c : '?';
  }
  return out.empty() ? (rest.empty() ? "the end" : "a blank") : "'" + out + "'";
}

// Well-formed UTF-8 as RFC 3629 has it (no overlong forms, surrogates or code points past
// U+10FFFF), which JSON writers insist on.
bool valid_utf8(std::string_view s) {
  const auto at = [&](std::size_t i) { return i < s.size() ? static_cast<unsigned char>(s[i]) : 0u; };
  for (std::size_t i = 0; i < s.size();) {
    const unsigned c = at(i);
    if (c < 0x80) {
      ++i;
      continue;
    }
    int n = 0;          // continuation bytes
    unsigned lo = 0x80, hi = 0xBF;  // the range of the first of them
    if (c >= 0xC2 && c <= 0xDF) n = 1;
    else if (c >= 0xE0 && c <= 0xEF) n = 2, lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
    else if (c >= 0xF0 && c <= 0xF4) n = 3, lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
    else return false;
    if (at(i + 1) < lo || at(i + 1) > hi) return false;
    for (int k = 2; k <= n; ++k)
      if ((at(i + static_cast<std::size_t>(k)) & 0xC0) != 0x80) return false;
    i += static_cast<std::size_t>(n) + 1;
  }
  return true;
}

// A DBC string as UTF-8 on one line: files from Windows tools are often Latin-1 ("°C" as the
// one byte 0xB0), which is re-encoded when the string is not UTF-8; control characters
// become '?'.
std::string text_of(std::string_view raw) {
  const bool utf8 = valid_utf8(raw);
  std::string out;
  for (char ch : raw) {
    const auto c = static_cast<unsigned char>(ch);
    if (c < 0x20 || c == 0x7F) {
      out += '?';
    } else if (c >= 0x80 && !utf8) {
      out += static_cast<char>(0xC0 | (c >> 6));
      out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
      out += ch;
    }
  }
  return out;
}

// Reads the tokens of one statement (one line, or up to ';'), counting lines for errors.
class Cursor {
 public:
  Cursor(std::string_view text, int line) : rest_(text), line_(line) {}

  int line() const { return line_; }
  bool at_end() {
    skip_space();
    return rest_.empty();
  }
  std::string_view rest() const { return rest_; }

  bool eat(char c) {
    skip_space();
    if (rest_.empty() || rest_.front() != c) return false;
    rest_.remove_prefix(1);
    return true;
  }
  // A name: letters, digits and '_' (DBC names are C identifiers; keywords and numbers read as one).
  std::string_view name() {
    skip_space();
    std::size_t n = 0;
    while (n < rest_.size() && is_name_char(rest_[n])) ++n;
    const auto out = rest_.substr(0, n);
    rest_.remove_prefix(n);
    return out;
  }
  // A quoted string (a backslash escapes the next character); nullopt when there is none or it
  // does not end.
  std::optional<std::string_view> quoted() {
    skip_space();
    if (rest_.empty() || rest_.front() != '"') return std::nullopt;
    std::size_t i = 1;
    int lines = 0;
    for (; i < rest_.size() && rest_[i] != '"'; ++i) {
      if (rest_[i] == '\n') ++lines;
      if (rest_[i] == '\\' && i + 1 < rest_.size()) ++i;
    }
    if (i >= rest_.size()) return std::nullopt;
    const auto out = rest_.substr(1, i - 1);
    rest_.remove_prefix(i + 1);
    line_ += lines;
    return out;
  }
  // A finite decimal number ("1E-005", "+3" and "-40" included).
  std::optional<double> number() {
    skip_space();
    std::string_view s = rest_;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc() || !std::isfinite(v)) return std::nullopt;
    rest_.remove_prefix(static_cast<std::size_t>(end - rest_.data()));
    return v;
  }
  template <typename Int>
  std::optional<Int> integer() {
    skip_space();
    std::string_view s = rest_;
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    Int v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (ec != std::errc()) return std::nullopt;
    if (end < s.data() + s.size() && (is_name_char(*end) || *end == '.')) return std::nullopt;  // "12abc", "1.5"
    rest_.remove_prefix(static_cast<std::size_t>(end - rest_.data()));
    return v;
  }
  // What is next, for an error message.
  std::string next() {
    skip_space();
    return shown(rest_);
  }
  // Where the next token starts: an error about a value read from there shows shown(peek()).
  std::string_view peek() {
    skip_space();
    return rest_;
  }

 private:
  void skip_space() {
    while (!rest_.empty() && is_space(rest_.front())) {
      if (rest_.front() == '\n') ++line_;
      rest_.remove_prefix(1);
    }
  }
  std::string_view rest_;
  int line_;
};

std::uint64_t key_of(std::uint32_t id, bool extended) { return id | (std::uint64_t{extended} << 32); }

class Reader {
 public:
  Reader(std::string_view text, const std::string& name) : text_(text), name_(name) { dbc_.path = name; }

  std::expected<Dbc, std::string> run() {
    std::size_t pos = 0;
    int line = 1;
    bool in_namespace = false;  // NS_'s list of keywords, which must not read as sections
    while (pos < text_.size() && error_.empty()) {
      const std::size_t eol = std::min(text_.find('\n', pos), text_.size());
      const std::string_view whole = text_.substr(pos, eol - pos);
      Cursor c(whole, line);
      const bool indented = !whole.empty() && is_space(whole.front());
      const std::string_view keyword = c.name();
      if (in_namespace && (indented || c.at_end() || (!keyword.empty() && Cursor(c.rest(), line).at_end()))) {
        pos = eol + 1;
        ++line;
        continue;
      }
      in_namespace = false;
      const bool statement = std::find(kStatementSections.begin(), kStatementSections.end(), keyword) !=
                             kStatementSections.end();
      if (statement) {
        const std::size_t end = statement_end(pos);
        if (end == std::string_view::npos) {
          fail(line, std::string(keyword) + " has no ';' at its end (a '\"' not closed?)");
          break;
        }
        Cursor s(text_.substr(pos, end - pos), line);
        s.name();
        read_statement(keyword, s);
        const std::string_view consumed = text_.substr(pos, end + 1 - pos);
        line += static_cast<int>(std::count(consumed.begin(), consumed.end(), '\n'));
        pos = end + 1;
        continue;
      }
      if (keyword == "NS_") in_namespace = true;
      else if (keyword == "BO_") read_message(c);
      else if (keyword == "SG_") read_signal(c);
      // VERSION, BS_, BU_ and anything unknown: one line, skipped.
      pos = eol + 1;
      ++line;
    }
    if (error_.empty()) finish();
    if (!error_.empty()) return std::unexpected(error_);
    return std::move(dbc_);
  }

 private:
  void fail(int line, const std::string& what) {
    if (error_.empty()) error_ = name_ + ":" + std::to_string(line) + ": " + what;
  }
  void warn(int line, const std::string& what) {
    if (dbc_.warnings.size() < kKeptWarnings) dbc_.warnings.push_back(name_ + ":" + std::to_string(line) + ": " + what);
  }

  // The ';' that ends the statement starting at pos (quotes skipped), npos when none does
  // before the end or before a line (outside quotes) that starts a message or a signal: a
  // missing ';' must not swallow the frames that follow.
  std::size_t statement_end(std::size_t pos) const {
    bool quoted = false;
    for (std::size_t i = pos; i < text_.size(); ++i) {
      const char ch = text_[i];
      if (quoted && ch == '\\') {
        ++i;
      } else if (ch == '"') {
        quoted = !quoted;
      } else if (!quoted && ch == ';') {
        return i;
      } else if (!quoted && ch == '\n') {
        const std::size_t next = text_.find_first_not_of(" \t\r", i + 1);
        if (next != std::string_view::npos &&
            (text_.compare(next, 4, "BO_ ") == 0 || text_.compare(next, 4, "SG_ ") == 0))
          return std::string_view::npos;
      }
    }
    return std::string_view::npos;
  }

  // BO_ <id> <name>: <length> <sender>
  void read_message(Cursor& c) {
    skipping_signals_ = false;
    const int line = c.line();
    const auto raw_id = c.integer<std::uint32_t>();
    if (!raw_id) return fail(line, "BO_: expected the message id (a number up to 4294967295), got " + c.next());
    const std::string_view name = c.name();
    if (name.empty()) return fail(line, "BO_ " + std::to_string(*raw_id) + ": expected the message name, got " + c.next());
    if (!c.eat(':')) return fail(line, "BO_ " + std::string(name) + ": expected ':' after the name, got " + c.next());
    const std::string_view at_length = c.peek();
    const auto length = c.integer<int>();
    if (!length || *length < 0 || *length > kMaxFrameBytes)
      return fail(line, "BO_ " + std::string(name) + ": expected the length in bytes (0..64), got " + shown(at_length));
    // The pseudo message of signals that are in no frame (id 0xC0000000): not a frame.
    if (name == "VECTOR__INDEPENDENT_SIG_MSG" || (*raw_id & ~kExtendedFlag & ~kIdMask) != 0) {
      if (name != "VECTOR__INDEPENDENT_SIG_MSG")
        return fail(line, "BO_ " + std::string(name) + ": id " + std::to_string(*raw_id) +
                              " has bits beyond 29 (other than bit 31, the 29-bit flag)");
      skipping_signals_ = true;
      current_ = -1;
      return;
    }
    DbcMessage m;
    m.id = *raw_id & kIdMask;
    m.extended = (*raw_id & kExtendedFlag) != 0 || m.id > kMaxStandardId;
    m.name = std::string(name);
    m.length = *length;
    m.sender = std::string(c.name());
    m.line = line;
    const auto [it, fresh] = by_id_.emplace(key_of(m.id, m.extended), dbc_.messages.size());
    if (!fresh) {
      const DbcMessage& other = dbc_.messages[it->second];
      return fail(line, "BO_ " + m.name + ": id " + std::to_string(*raw_id) + " is also " + other.name + "'s (line " +
                            std::to_string(other.line) + ")");
    }
    current_ = static_cast<int>(dbc_.messages.size());
    dbc_.messages.push_back(std::move(m));
    signal_names_.emplace_back();
  }

  // SG_ <name> [M|m<n>] : <start>|<length>@<order><sign> (<factor>,<offset>) [<min>|<max>] "<unit>" <receivers>
  void read_signal(Cursor& c) {
    if (skipping_signals_) return;
    const int line = c.line();
    if (current_ < 0) return fail(line, "SG_ before any BO_: a signal must follow its message");
    DbcMessage& m = dbc_.messages[static_cast<std::size_t>(current_)];
    DbcSignal s;
    s.line = line;
    s.name = std::string(c.name());
    if (s.name.empty()) return fail(line, "SG_: expected the signal name, got " + c.next());
    const std::string where = "SG_ " + s.name + " (in " + m.name + ")";
    const std::string_view mux = c.name();
    if (mux == "M") {
      s.multiplexing = Multiplexing::Multiplexor;
    } else if (mux.size() >= 2 && mux.front() == 'm') {
      if (mux.back() == 'M')
        return fail(line, where + ": extended multiplexing ('" + std::string(mux) + "', a multiplexed multiplexor) is not supported");
      std::uint64_t v = 0;
      const auto [end, ec] = std::from_chars(mux.data() + 1, mux.data() + mux.size(), v);
      if (ec != std::errc() || end != mux.data() + mux.size())
        return fail(line, where + ": expected M or m<number> before ':', got '" + std::string(mux) + "'");
      s.multiplexing = Multiplexing::Multiplexed;
      s.multiplexer_value = v;
    } else if (!mux.empty()) {
      return fail(line, where + ": expected M or m<number> before ':', got '" + std::string(mux) + "'");
    }
    if (!c.eat(':')) return fail(line, where + ": expected ':' after the name, got " + c.next());
    const std::string_view at_start = c.peek();
    const auto start = c.integer<int>();
    if (!start || *start < 0 || *start >= 8 * kMaxFrameBytes)
      return fail(line, where + ": expected the start bit (0..511), got " + shown(at_start));
    s.start_bit = *start;
    if (!c.eat('|')) return fail(line, where + ": expected '|' after the start bit, got " + c.next());
    const std::string_view at_length = c.peek();
    const auto length = c.integer<int>();
    if (!length || *length < 1 || *length > 64)
      return fail(line, where + ": expected the length in bits (1..64), got " + shown(at_length));
    s.length = *length;
    if (!c.eat('@')) return fail(line, where + ": expected '@' after the length, got " + c.next());
    if (c.eat('1')) s.byte_order = ByteOrder::Intel;
    else if (c.eat('0')) s.byte_order = ByteOrder::Motorola;
    else return fail(line, where + ": expected the byte order after '@' (1 Intel, 0 Motorola), got " + c.next());
    if (c.eat('-')) s.is_signed = true;
    else if (!c.eat('+')) return fail(line, where + ": expected '+' (unsigned) or '-' (signed) after the byte order, got " + c.next());
    const auto factor = (c.eat('(') ? c.number() : std::nullopt);
    const auto offset = factor && c.eat(',') ? c.number() : std::nullopt;
    if (!factor || !offset || !c.eat(')'))
      return fail(line, where + ": expected (factor,offset) as two finite numbers, got " + c.next());
    const auto min = (c.eat('[') ? c.number() : std::nullopt);
    const auto max = min && c.eat('|') ? c.number() : std::nullopt;
    if (!min || !max || !c.eat(']')) return fail(line, where + ": expected [min|max] as two finite numbers, got " + c.next());
    s.factor = *factor;
    s.offset = *offset;
    s.min = *min;
    s.max = *max;
    const auto unit = c.quoted();
    if (!unit) return fail(line, where + ": expected the unit in quotes, got " + c.next());
    s.unit = text_of(*unit);  // the receivers that follow are not needed to decode
    // Beyond any frame is an error; beyond the message's stated length only a warning: such
    // files are in use (one of the real test files has one), and the signal decodes from a
    // frame long enough to hold it.
    const std::string bits = std::to_string(s.start_bit) + "|" + std::to_string(s.length) + "@" +
                             (s.byte_order == ByteOrder::Intel ? "1" : "0");
    if (bytes_needed(s) > kMaxFrameBytes)
      return fail(line, where + ": bits " + bits + " run beyond the 64 bytes of any CAN frame");
    if (bytes_needed(s) > m.length)
      warn(line, where + ": bits " + bits + " need " + std::to_string(bytes_needed(s)) + " bytes, beyond the message's " +
                     std::to_string(m.length) + ": decoded only from frames that long");
    if (s.multiplexing == Multiplexing::Multiplexor) {
      if (m.multiplexor >= 0)
        return fail(line, where + ": a second multiplexor (M) in the message (the first is " +
                              m.signals[static_cast<std::size_t>(m.multiplexor)].name + "); extended multiplexing is not supported");
      m.multiplexor = static_cast<int>(m.signals.size());
    }
    auto& names = signal_names_[static_cast<std::size_t>(current_)];
    const auto [it, fresh] = names.emplace(s.name, m.signals.size());
    if (!fresh)
      return fail(line, where + ": the message already has a signal of this name (line " +
                            std::to_string(m.signals[it->second].line) + ")");
    m.signals.push_back(std::move(s));
  }

  void read_statement(std::string_view keyword, Cursor& c) {
    if (keyword == "VAL_") read_values(c);
    else if (keyword == "SIG_VALTYPE_") read_value_type(c);
    else if (keyword == "BA_DEF_DEF_") read_attribute_default(c);
    else if (keyword == "BA_") read_attribute(c);
  }

  // The message and signal a VAL_ or SIG_VALTYPE_ names; nullptr after an error.
  DbcSignal* signal_of(Cursor& c, std::uint32_t raw_id, const char* keyword) {
    const int line = c.line();
    const std::uint32_t id = raw_id & kIdMask;
    const bool extended = (raw_id & kExtendedFlag) != 0 || id > kMaxStandardId;
    const std::string_view name = c.name();
    const auto m = by_id_.find(key_of(id, extended));
    if (m == by_id_.end()) {
      fail(line, std::string(keyword) + " " + std::to_string(raw_id) + " " + std::string(name) + ": no BO_ has this id");
      return nullptr;
    }
    const auto& names = signal_names_[m->second];
    const auto s = names.find(std::string(name));
    DbcMessage& msg = dbc_.messages[m->second];
    if (s == names.end()) {
      fail(line, std::string(keyword) + " " + std::to_string(raw_id) + ": message " + msg.name + " has no signal " +
                     (name.empty() ? c.next() : "'" + std::string(name) + "'"));
      return nullptr;
    }
    return &msg.signals[s->second];
  }

  // VAL_ <id> <signal> <value> "<text>" ... ;   (VAL_ of an environment variable is skipped)
  void read_values(Cursor& c) {
    const auto raw_id = c.integer<std::uint32_t>();
    if (!raw_id) return;  // VAL_ <environment variable> ...
    DbcSignal* s = signal_of(c, *raw_id, "VAL_");
    if (!s) return;
    while (!c.at_end()) {
      const auto value = c.number();
      const auto text = value ? c.quoted() : std::nullopt;
      if (!value || !text || *value != std::floor(*value) || std::abs(*value) > 9.2e18)
        return fail(c.line(), "VAL_ " + std::to_string(*raw_id) + " " + s->name + ": expected <integer> \"<text>\" pairs, got " +
                                  c.next());
      s->values[static_cast<std::int64_t>(*value)] = text_of(*text);
    }
  }

  // SIG_VALTYPE_ <id> <signal> : <0 integer | 1 float | 2 double> ;
  void read_value_type(Cursor& c) {
    const int line = c.line();
    const auto raw_id = c.integer<std::uint32_t>();
    if (!raw_id) return fail(line, "SIG_VALTYPE_: expected the message id, got " + c.next());
    DbcSignal* s = signal_of(c, *raw_id, "SIG_VALTYPE_");
    if (!s) return;
    c.eat(':');  // some writers leave it out
    const std::string_view at_type = c.peek();
    const auto type = c.integer<int>();
    const int needed = type == 1 ? 32 : type == 2 ? 64 : 0;
    if (!type || *type < 0 || *type > 2)
      return fail(line, "SIG_VALTYPE_ " + s->name + ": expected 0 (integer), 1 (float) or 2 (double), got " + shown(at_type));
    if (needed && s->length != needed)
      return fail(line, "SIG_VALTYPE_ " + s->name + ": " + (*type == 1 ? "a float" : "a double") + " needs " +
                            std::to_string(needed) + " bits, the signal has " + std::to_string(s->length));
    s->value_type = *type == 1 ? SignalValueType::Float32 : *type == 2 ? SignalValueType::Float64 : SignalValueType::Integer;
  }

  // A GenMsgCycleTime value in ms: a whole number 0..10^7 (0: not periodic).
  std::optional<int> cycle_time(Cursor& c, const std::string& where) {
    const int line = c.line();
    const std::string_view at = c.peek();
    const auto v = c.number();
    if (!v || *v < 0 || *v > 1e7 || *v != std::floor(*v)) {
      fail(line, where + ": expected the cycle time in ms (a whole number 0..10000000), got " + shown(at));
      return std::nullopt;
    }
    return static_cast<int>(*v);
  }

  // BA_DEF_DEF_ "GenMsgCycleTime" <ms> ;  (other defaults are skipped)
  void read_attribute_default(Cursor& c) {
    const auto name = c.quoted();
    if (!name || *name != kCycleTime) return;
    if (const auto v = cycle_time(c, "BA_DEF_DEF_ \"GenMsgCycleTime\"")) default_cycle_ms_ = *v;
  }

  // BA_ "GenMsgCycleTime" BO_ <id> <ms> ;  (other attributes are skipped)
  void read_attribute(Cursor& c) {
    const int line = c.line();
    const auto name = c.quoted();
    if (!name || *name != kCycleTime) return;
    if (c.name() != "BO_") return fail(line, "BA_ \"GenMsgCycleTime\": expected BO_ <id> <ms>, got " + c.next());
    const auto raw_id = c.integer<std::uint32_t>();
    if (!raw_id) return fail(line, "BA_ \"GenMsgCycleTime\" BO_: expected the message id, got " + c.next());
    const std::uint32_t id = *raw_id & kIdMask;
    const auto m = by_id_.find(key_of(id, (*raw_id & kExtendedFlag) != 0 || id > kMaxStandardId));
    if (m == by_id_.end()) return fail(line, "BA_ \"GenMsgCycleTime\" BO_ " + std::to_string(*raw_id) + ": no BO_ has this id");
    if (const auto v = cycle_time(c, "BA_ \"GenMsgCycleTime\" BO_ " + std::to_string(*raw_id))) cycle_ms_[m->second] = *v;
  }

  void finish() {
    for (std::size_t i = 0; i < dbc_.messages.size(); ++i) {
      DbcMessage& m = dbc_.messages[i];
      const auto own = cycle_ms_.find(i);
      const int ms = own != cycle_ms_.end() ? own->second : default_cycle_ms_;
      if (ms > 0) m.cycle_time_ms = ms;
      if (m.multiplexor >= 0) continue;
      for (const DbcSignal& s : m.signals)
        if (s.multiplexing == Multiplexing::Multiplexed)
          return fail(s.line, "SG_ " + s.name + " (in " + m.name + "): multiplexed (m" +
                                  std::to_string(s.multiplexer_value) + ") but the message has no multiplexor (M)");
    }
  }

  std::string_view text_;
  const std::string& name_;
  Dbc dbc_;
  std::string error_;
  int current_ = -1;               // the message SG_ lines belong to
  bool skipping_signals_ = false;  // SG_ lines of VECTOR__INDEPENDENT_SIG_MSG
  std::map<std::uint64_t, std::size_t> by_id_;
  std::vector<std::map<std::string, std::size_t>> signal_names_;  // per message: name -> index
  std::map<std::size_t, int> cycle_ms_;                            // message index -> BA_ GenMsgCycleTime
  int default_cycle_ms_ = 0;
};

}  // namespace

const DbcSignal* DbcMessage::signal(std::string_view name) const {
  for (const DbcSignal& s : signals)
    if (s.name == name) return &s;
  return nullptr;
}

const DbcMessage* Dbc::find(std::uint32_t id, bool extended) const {
  for (const DbcMessage& m : messages)
    if (m.id == id && m.extended == extended) return &m;
  return nullptr;
}

const DbcMessage* Dbc::find(std::string_view name) const {
  for (const DbcMessage& m : messages)
    if (m.name == name) return &m;
  return nullptr;
}

std::expected<Dbc, std::string> parse_dbc(std::string_view text, const std::string& name) {
  return Reader(text, name).run();
}

std::expected<Dbc, std::string> load_dbc(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return std::unexpected(path + ": is a directory, expected a DBC file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::unexpected(path + ": cannot open (" + std::strerror(errno) + ")");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) return std::unexpected(path + ": read error");
  return parse_dbc(text.str(), path);
}

}  // namespace epichead::firmware_iface
