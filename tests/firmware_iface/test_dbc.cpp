// The DBC reader and signal decoder (dbc.h, dbc_decode.h): the real third-party database of
// ../shared/data/can (counts from its README), values worked out by hand for both byte orders,
// signed, float, multiplexed, extended-id and CAN FD signals, the sections that are skipped,
// and an error naming file and line for each kind of malformed input.
#include <catch2/catch.hpp>

#include <bit>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "epichead/firmware_iface/dbc.h"
#include "epichead/firmware_iface/dbc_decode.h"

using namespace epichead::firmware_iface;

namespace {

Dbc parse(const std::string& text) {
  auto d = parse_dbc(text, "t.dbc");
  INFO((d ? "" : d.error()));
  REQUIRE(d.has_value());
  return *d;
}

std::string error_of(const std::string& text) {
  auto d = parse_dbc(text, "t.dbc");
  REQUIRE_FALSE(d.has_value());
  return d.error();
}

template <std::size_t N>
std::optional<DbcValue> decode(const DbcSignal& s, const std::array<std::uint8_t, N>& data) {
  const auto bits = extract_bits(s, data);
  if (!bits) return std::nullopt;
  return decode_bits(s, *bits);
}

// Ten lines: what follows starts on line 11.
const std::string kHeader = "VERSION \"\"\n\nNS_ :\n\tCM_\n\tBA_DEF_\n\tVAL_\n\nBS_:\n\nBU_: N\n";

}  // namespace

TEST_CASE("The real anzen DBC reads with its 9 messages and 114 signals as its README counts them") {
  // README: 9 BO_, 114 SG_, 59 Intel, 55 Motorola, all unsigned, 4 multiplexors.
  auto d = load_dbc(std::string(EPICHEAD_SHARED_DATA) + "/can/canbus_visualizer_anzen.dbc");
  INFO((d ? "" : d.error()));
  REQUIRE(d.has_value());
  CHECK(d->messages.size() == 9);
  int signals = 0, intel = 0, motorola = 0, multiplexors = 0, multiplexed = 0;
  for (const auto& m : d->messages) {
    CHECK(m.extended);  // ids over 0x7FF written without bit 31
    CHECK(m.length == 8);
    CHECK_FALSE(m.cycle_time_ms.has_value());
    for (const auto& s : m.signals) {
      ++signals;
      intel += s.byte_order == ByteOrder::Intel;
      motorola += s.byte_order == ByteOrder::Motorola;
      multiplexors += s.multiplexing == Multiplexing::Multiplexor;
      multiplexed += s.multiplexing == Multiplexing::Multiplexed;
      CHECK_FALSE(s.is_signed);
    }
  }
  CHECK(signals == 114);
  CHECK(intel == 59);
  CHECK(motorola == 55);
  CHECK(multiplexors == 4);
  CHECK(multiplexed == 80);  // grep -cE 'SG_ \w+ m[0-9]+ ': 80 (the README's 84 counts the 4 M too)
  const DbcMessage* m = d->find(0x183ECCE8, true);
  REQUIRE(m != nullptr);
  CHECK(m->name == "TEMP_VOLTAGE_FRAME");
  CHECK(d->find(0x183ECCE8, false) == nullptr);
  // power_cumulative 48|16@0+ runs into a ninth byte: read, with a warning naming its line.
  REQUIRE(d->warnings.size() == 1);
  CHECK(d->warnings[0].find("canbus_visualizer_anzen.dbc:47: SG_ power_cumulative (in POWER_CURRENT)") != std::string::npos);
}

TEST_CASE("Motorola and Intel signals of the real log's first frame decode to the values worked out by hand") {
  auto d = load_dbc(std::string(EPICHEAD_SHARED_DATA) + "/can/canbus_visualizer_anzen.dbc");
  REQUIRE(d.has_value());
  const DbcMessage& m = *d->find("TEMP_VOLTAGE_FRAME");
  // (1605726422.019523) vcan0 183ECCE8#4139E9391A444540
  const std::array<std::uint8_t, 8> data = {0x41, 0x39, 0xE9, 0x39, 0x1A, 0x44, 0x45, 0x40};
  // temperature_diode 0|8@1+ (1,-40): byte 0 = 65 -> 25
  CHECK(decode(*m.signal("temperature_diode"), data)->physical == 25);
  // voltage_max_mono 40|16@0+ (0.001,0): MSB = byte 5 bit 0 (0), byte 6 (0x45), byte 7 bits
  // 7..1 (0100000): 0 01000101 0100000 = 8864 -> 8.864 V
  const DbcValue vmax = *decode(*m.signal("voltage_max_mono"), data);
  CHECK(vmax.bits == 8864);
  CHECK(vmax.physical == Approx(8.864));
  // voltage_min_mono 24|16@0+: byte 3 bit 0 (1), byte 4 (0x1A), byte 5 bits 7..1 (0100010):
  // 1 00011010 0100010 = 36130
  CHECK(decode(*m.signal("voltage_min_mono"), data)->bits == 36130);
}

TEST_CASE("Signed signals are sign-extended in both byte orders, then scaled and offset") {
  const Dbc d = parse(kHeader +
                      "BO_ 256 S: 8 N\n"
                      " SG_ moto : 7|12@0- (0.5,1) [-1000|1000] \"x\" N\n"
                      " SG_ intel : 20|12@1- (0.25,0) [0|0] \"y\" N\n");
  const DbcMessage& m = d.messages.at(0);
  CHECK_FALSE(m.extended);
  // moto: byte 0 (0xFE) then byte 1 bits 7..4 (0xD): 0xFED = 4077 = -19 in 12 bits -> -19 * 0.5 + 1
  // intel: bits 20..31: byte 2 bits 4..7 (0xE) then byte 3 (0xFF): 0xFFE = -2 -> -0.5
  const std::array<std::uint8_t, 8> data = {0xFE, 0xD0, 0xE0, 0xFF, 0, 0, 0, 0};
  const DbcValue moto = *decode(m.signals[0], data);
  CHECK(moto.raw == -19);
  CHECK(moto.raw_signed(m.signals[0]) == -19);
  CHECK(moto.physical == -8.5);
  const DbcValue intel = *decode(m.signals[1], data);
  CHECK(intel.raw == -2);
  CHECK(intel.physical == -0.5);
  CHECK(m.signals[0].has_range());
  CHECK_FALSE(m.signals[1].has_range());
}

TEST_CASE("SIG_VALTYPE_ signals decode as IEEE float and double") {
  const Dbc d = parse(kHeader +
                      "BO_ 300 F: 16 N\n"
                      " SG_ f : 0|32@1- (2,0) [0|0] \"\" N\n"
                      " SG_ g : 71|64@0- (1,0) [0|0] \"\" N\n\n"
                      "SIG_VALTYPE_ 300 f : 1;\nSIG_VALTYPE_ 300 g : 2;\n");
  const DbcMessage& m = d.messages.at(0);
  REQUIRE(m.signals[0].value_type == SignalValueType::Float32);
  REQUIRE(m.signals[1].value_type == SignalValueType::Float64);
  std::array<std::uint8_t, 16> data{};
  const auto f = std::bit_cast<std::uint32_t>(1.5f);
  std::memcpy(data.data(), &f, 4);  // little endian: Intel
  const auto g = std::bit_cast<std::uint64_t>(2.25);
  for (int i = 0; i < 8; ++i) data[static_cast<std::size_t>(8 + i)] = static_cast<std::uint8_t>(g >> (56 - 8 * i));  // big endian
  CHECK(decode(m.signals[0], data)->raw == 1.5);
  CHECK(decode(m.signals[0], data)->physical == 3.0);
  CHECK(decode(m.signals[1], data)->physical == 2.25);
}

TEST_CASE("A multiplexed frame carries the signals its multiplexor value selects and the plain ones") {
  const Dbc d = parse(kHeader +
                      "BO_ 301 Mux: 8 N\n"
                      " SG_ sel M : 0|8@1+ (1,0) [0|0] \"\" N\n"
                      " SG_ a m1 : 8|8@1+ (1,0) [0|0] \"\" N\n"
                      " SG_ b m2 : 8|16@1+ (1,0) [0|0] \"\" N\n"
                      " SG_ c : 56|8@1+ (1,0) [0|0] \"\" N\n");
  const DbcMessage& m = d.messages.at(0);
  CHECK(m.multiplexor == 0);
  std::vector<DbcValue> out(m.signals.size());
  const std::array<std::uint8_t, 8> two = {2, 0x34, 0x12, 0, 0, 0, 0, 7};
  const DbcFrameDecode r = decode_frame(m, two, out);
  REQUIRE(r.values == 3);
  CHECK(*r.multiplexer == 2);
  CHECK(m.signals[out[0].signal].name == "sel");
  CHECK(m.signals[out[1].signal].name == "b");
  CHECK(out[1].physical == 0x1234);
  CHECK(m.signals[out[2].signal].name == "c");
  const std::array<std::uint8_t, 8> nine = {9, 0, 0, 0, 0, 0, 0, 0};
  CHECK(decode_frame(m, nine, out).values == 2);  // sel and c: no signal for 9
}

TEST_CASE("Bit 31 of a BO_ id marks a 29-bit id and CAN FD messages reach byte 63") {
  const Dbc d = parse(kHeader +
                      "BO_ 2147483905 Fd: 64 N\n"
                      " SG_ last : 504|8@1+ (1,0) [0|0] \"\" N\n"
                      "BO_ 257 Std: 8 N\n");
  REQUIRE(d.find(0x101, true) != nullptr);
  REQUIRE(d.find(0x101, false) != nullptr);
  CHECK(d.find(0x101, true)->name == "Fd");
  const DbcMessage& m = *d.find("Fd");
  std::array<std::uint8_t, 64> data{};
  data[63] = 0xAB;
  std::vector<DbcValue> out(1);
  CHECK(decode_frame(m, data, out).values == 1);
  CHECK(out[0].physical == 0xAB);
  const DbcFrameDecode short_frame = decode_frame(m, std::span(data.data(), 8), out);
  CHECK(short_frame.values == 0);
  CHECK(short_frame.too_short == 1);
}

TEST_CASE("VAL_ texts, GenMsgCycleTime and the skipped sections of a full DBC") {
  const Dbc d = parse(kHeader +
                      "VAL_TABLE_ States 0 \"Off\" 1 \"On\" ;\n"
                      "BO_ 3221225472 VECTOR__INDEPENDENT_SIG_MSG: 0 Vector__XXX\n"
                      " SG_ orphan : 0|8@1+ (1,0) [0|0] \"\" Vector__XXX\n\n"
                      "BO_ 16 A: 8 N\n SG_ mode : 0|2@1+ (1,0) [0|3] \"\" N\n\n"
                      "BO_ 17 B: 8 N\n SG_ t : 0|8@1+ (1,-40) [-40|215] \"\xB0" "C\" N\n\n"
                      "BO_TX_BU_ 16 : N;\n"
                      "EV_ Env: 0 [0|1] \"\" 0 1 DUMMY_NODE_VECTOR0 Vector__XXX;\n"
                      "CM_ BO_ 16 \"A comment; with a semicolon\nover two lines\";\n"
                      "CM_ SG_ 16 mode \"quote \\\" inside\";\n"
                      "BA_DEF_ BO_ \"GenMsgCycleTime\" INT 0 10000;\n"
                      "BA_DEF_ \"BusType\" STRING ;\n"
                      "BA_DEF_DEF_ \"BusType\" \"CAN\";\n"
                      "BA_DEF_DEF_ \"GenMsgCycleTime\" 50;\n"
                      "BA_ \"BusType\" \"CAN\";\n"
                      "BA_ \"GenMsgCycleTime\" BO_ 16 10;\n"
                      "VAL_ 16 mode 0 \"Off\" 1 \"Position\" 2 \"Rate\" 3 \"Safe Stop\" ;\n"
                      "VAL_ Env 0 \"no\" ;\n"
                      "SIG_GROUP_ 16 G 1 : mode;\n");
  REQUIRE(d.messages.size() == 2);  // the pseudo message is not a frame
  const DbcMessage& a = *d.find("A");
  CHECK(a.cycle_time_ms == 10);
  CHECK(d.find("B")->cycle_time_ms == 50);  // BA_DEF_DEF_
  CHECK(value_text(a.signals[0], 3) == "Safe Stop");
  CHECK(value_text(a.signals[0], 4).empty());
  CHECK(d.find("B")->signals[0].unit == "\xC2\xB0" "C");  // Latin-1 degree sign as UTF-8
  CHECK(a.line == 15);
  CHECK(d.find("B")->signals[0].line == 19);
}

TEST_CASE("Bits written by insert_bits read back and match the big-endian word formula for Motorola") {
  std::mt19937_64 rng(7);
  for (int order = 0; order < 2; ++order) {
    for (int start = 0; start < 64; ++start) {
      for (int length = 1; length <= 64; ++length) {
        DbcSignal s;
        s.start_bit = start;
        s.length = length;
        s.byte_order = order == 0 ? ByteOrder::Intel : ByteOrder::Motorola;
        if (bytes_needed(s) > 8) continue;
        INFO("start " << start << " length " << length << " order " << order);
        const std::uint64_t value = length == 64 ? rng() : rng() & ((std::uint64_t{1} << length) - 1);
        std::array<std::uint8_t, 8> data{};
        REQUIRE(insert_bits(s, value, data));
        CHECK(*extract_bits(s, data) == value);
        std::uint64_t word = 0;  // the frame as a little-endian and as a big-endian 64-bit word
        for (int i = 0; i < 8; ++i) word |= std::uint64_t{data[static_cast<std::size_t>(i)]} << (8 * i);
        if (order == 0) {
          CHECK((length == 64 ? word : (word >> start) & ((std::uint64_t{1} << length) - 1)) == value);
        } else {
          const std::uint64_t be = std::byteswap(word);
          const int msb_from_top = 8 * (start / 8) + 7 - start % 8;  // 0 = bit 7 of byte 0
          CHECK(((be << msb_from_top) >> (64 - length)) == value);
        }
        int ones = 0;  // nothing outside the signal was written
        for (auto b : data) ones += std::popcount(b);
        CHECK(ones == std::popcount(value));
      }
    }
  }
}

TEST_CASE("Malformed DBC input gives one error naming the file, the line and what is wrong") {
  const std::string bo = kHeader + "BO_ 256 M: 8 N\n";  // line 11
  const auto has = [](const std::string& e, const std::string& part) {
    INFO(e);
    CHECK(e.find(part) != std::string::npos);
    CHECK(e.find('\n') == std::string::npos);
  };
  has(error_of(bo + " SG_ a : 0|8@1+ (1,0) [0|"), "t.dbc:12: SG_ a (in M): expected [min|max]");
  has(error_of(bo + " SG_ a : 0|8@2+ (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): expected the byte order after '@' (1 Intel, 0 Motorola), got '2+'");
  has(error_of(bo + " SG_ a : 0|8@1* (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): expected '+' (unsigned) or '-' (signed)");
  has(error_of(bo + " SG_ a : 600|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): expected the start bit (0..511), got '600|8@1+'");
  has(error_of(kHeader + "BO_ 256 M: 64 N\n SG_ a : 511|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): bits 511|8@1 run beyond the 64 bytes");
  has(error_of(bo + " SG_ a : 0|0@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): expected the length in bits (1..64), got '0@1+'");
  has(error_of(bo + " SG_ a : 0|8@1+ (x,0) [0|0] \"\" N\n"), "expected (factor,offset) as two finite numbers, got 'x,0)'");
  has(error_of(bo + " SG_ a : 0|8@1+ (1,0) [0|0] \"unit N\n"), "t.dbc:12: SG_ a (in M): expected the unit in quotes");
  has(error_of(kHeader + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:11: SG_ before any BO_");
  has(error_of(bo + "BO_ 256 Again: 8 N\n"), "t.dbc:12: BO_ Again: id 256 is also M's (line 11)");
  has(error_of(kHeader + "BO_ 256 M: 65 N\n"), "t.dbc:11: BO_ M: expected the length in bytes (0..64), got '65'");
  has(error_of(kHeader + "BO_ 0x100 M: 8 N\n"), "t.dbc:11: BO_: expected the message id");
  has(error_of(bo + " SG_ a m1 : 8|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:12: SG_ a (in M): multiplexed (m1) but the message has no multiplexor (M)");
  has(error_of(bo + " SG_ a M : 0|8@1+ (1,0) [0|0] \"\" N\n SG_ b M : 8|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:13: SG_ b (in M): a second multiplexor");
  has(error_of(bo + " SG_ a m1M : 0|8@1+ (1,0) [0|0] \"\" N\n"), "extended multiplexing ('m1M'");
  has(error_of(bo + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\n SG_ a : 8|8@1+ (1,0) [0|0] \"\" N\n"), "t.dbc:13: SG_ a (in M): the message already has a signal of this name (line 12)");
  has(error_of(bo + " SG_ a : 0|16@1+ (1,0) [0|0] \"\" N\nSIG_VALTYPE_ 256 a : 1;\n"), "t.dbc:13: SIG_VALTYPE_ a: a float needs 32 bits, the signal has 16");
  has(error_of(bo + "VAL_ 999 a 0 \"x\" ;\n"), "t.dbc:12: VAL_ 999 a: no BO_ has this id");
  has(error_of(bo + " SG_ a : 0|8@1+ (1,0) [0|0] \"\" N\nVAL_ 256 a 0 ;\n"), "t.dbc:13: VAL_ 256 a: expected <integer> \"<text>\" pairs");
  has(error_of(bo + "CM_ BO_ 256 \"never closed;\n"), "t.dbc:12: CM_ has no ';' at its end");
  has(error_of(bo + "CM_ BO_ 256 \"closed\"\nBO_ 257 N: 8 N\n;"), "t.dbc:12: CM_ has no ';' at its end");
  has(error_of(bo + "BA_ \"GenMsgCycleTime\" BO_ 256 -5;\n"), "t.dbc:12: BA_ \"GenMsgCycleTime\" BO_ 256: expected the cycle time in ms");
  has(error_of(bo + "BA_ \"GenMsgCycleTime\" BO_ 257 5;\n"), "t.dbc:12: BA_ \"GenMsgCycleTime\" BO_ 257: no BO_ has this id");
  auto missing = load_dbc("/nonexistent/x.dbc");
  REQUIRE_FALSE(missing.has_value());
  CHECK(missing.error() == "/nonexistent/x.dbc: cannot open (No such file or directory)");
}

TEST_CASE("Units and VAL_ texts come out as well-formed UTF-8 on one line, whatever the file's bytes") {
  // "°C" in UTF-8 stays; 0xF5.. (no UTF-8 lead byte), an overlong "/" (C0 AF), a surrogate
  // (ED A0 80) and a cut sequence are taken as Latin-1; control characters become '?'.
  const auto unit_of = [](const std::string& unit) {
    return parse(kHeader + "BO_ 1 A: 8 N\n SG_ s : 0|8@1+ (1,0) [0|0] \"" + unit + "\" N\n").messages.at(0).signals.at(0).unit;
  };
  CHECK(unit_of("\xC2\xB0" "C") == "\xC2\xB0" "C");
  CHECK(unit_of("\xF5\x80\x80\x80") == "\xC3\xB5\xC2\x80\xC2\x80\xC2\x80");
  CHECK(unit_of("\xC0\xAF") == "\xC3\x80\xC2\xAF");
  CHECK(unit_of("\xED\xA0\x80") == "\xC3\xAD\xC2\xA0\xC2\x80");
  CHECK(unit_of("a\xE2\x82") == "a\xC3\xA2\xC2\x82");
  CHECK(unit_of("a\tb") == "a?b");
}

TEST_CASE("Text that is not a DBC reads as an empty database or an error, never more") {
  CHECK(parse("").messages.empty());
  CHECK(parse("hello world\n\x01\x02\x03\n").messages.empty());
  CHECK_FALSE(parse_dbc("BO_ 1 A: 8 N\n SG_ \xff", "t.dbc").has_value());
}
