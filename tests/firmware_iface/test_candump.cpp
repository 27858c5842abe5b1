// candump log lines (candump_line.h), the streaming reader and the writer: every line form,
// garbage, mutated lines, CRLF, comments, missing final newline, long lines, round trips.
#include <catch2/catch.hpp>

#include <cstdio>
#include <random>
#include <string>
#include <string_view>

#include "common/temp_dir.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/candump_writer.h"

using namespace epichead::firmware_iface;

namespace {

// The line is a view of the caller's text (a literal): the record's iface points into it.
CandumpRecord parse_ok(std::string_view line) {
  CandumpRecord r;
  const CandumpParse p = parse_candump_line(line, r);
  INFO(line << " -> " << p.reason);
  REQUIRE(p.kind == CandumpLineKind::Frame);
  return r;
}

CandumpParse parse(const std::string& line) {
  CandumpRecord r;
  return parse_candump_line(line, r);
}

}  // namespace

TEST_CASE("Classic 11-bit and 29-bit data frames parse with stamp, iface and bytes") {
  auto r = parse_ok("(1436509052.249713) can0 123#DEADBEEF");
  CHECK(r.has_stamp);
  CHECK(r.frame.stamp_us == 1436509052249713LL);
  CHECK(r.iface == "can0");
  CHECK(r.frame.frame.id == 0x123);
  CHECK_FALSE(r.frame.frame.extended());
  CHECK(r.frame.frame.len == 4);
  CHECK(r.frame.frame.data[0] == 0xDE);
  CHECK(r.frame.frame.data[3] == 0xEF);

  auto e = parse_ok("(1605726422.123456) vcan0 183ECCE8#0011223344556677");
  CHECK(e.frame.frame.extended());
  CHECK(e.frame.frame.id == 0x183ECCE8);
  CHECK(e.frame.frame.len == 8);

  auto empty = parse_ok("(1.000001) vcan0 5D1#");
  CHECK(empty.frame.frame.len == 0);
  CHECK(empty.frame.stamp_us == 1'000'001);

  auto dots = parse_ok("(1.5) can0 123#11.22.33");
  CHECK(dots.frame.frame.len == 3);
  CHECK(dots.frame.stamp_us == 1'500'000);  // short fractions are scaled
  auto dlc = parse_ok("(1.000000) can0 123#1122334455667788_C");
  CHECK(dlc.frame.frame.len == 8);
}

TEST_CASE("Remote, error and CAN FD frames parse with their flags") {
  auto rtr = parse_ok("(1.000000) can0 123#R");
  CHECK(rtr.frame.frame.remote());
  CHECK(rtr.frame.frame.len == 0);
  auto rtr4 = parse_ok("(1.000000) can0 1F334455#R4");
  CHECK(rtr4.frame.frame.remote());
  CHECK(rtr4.frame.frame.extended());
  CHECK(rtr4.frame.frame.len == 4);

  auto err = parse_ok("(1.000000) can0 20000004#0004000000000000");
  CHECK(err.frame.frame.error());
  CHECK_FALSE(err.frame.frame.extended());
  CHECK(err.frame.frame.id == 0x4);

  auto fd = parse_ok("(1.000000) vcan1 123##5" + std::string(64, 'A') + std::string(64, '5'));
  CHECK(fd.frame.frame.fd());
  CHECK(has(fd.frame.frame.flags, CanFlags::BitRateSwitch));
  CHECK_FALSE(has(fd.frame.frame.flags, CanFlags::ErrorStateIndicator));
  CHECK(fd.frame.frame.len == 64);
  auto fdf = parse_ok("(1.000000) vcan1 1F334455##F11");  // flag bit 0x08 is not defined: ignored
  CHECK(fdf.frame.frame.fd());
  CHECK(has(fdf.frame.frame.flags, CanFlags::ErrorStateIndicator));
  CHECK(fdf.frame.frame.len == 1);
}

TEST_CASE("Direction suffixes, CRLF, comments and blank lines") {
  CHECK(parse_ok("(1.000000) can0 123#00 R").direction == CanDirection::Received);
  CHECK(parse_ok("(1.000000) can0 123#00 T\r").direction == CanDirection::Transmitted);
  CHECK(parse_ok("(1.000000) can0 123#00\r").frame.frame.len == 1);
  CHECK(parse("").kind == CandumpLineKind::Skip);
  CHECK(parse("   \r").kind == CandumpLineKind::Skip);
  CHECK(parse("# recorded on the bench").kind == CandumpLineKind::Skip);
}

TEST_CASE("candump's default output parses, with and without timestamps") {
  auto r = parse_ok("  can0  680   [8]  03 22 01 00 00 00 00 00");
  CHECK_FALSE(r.has_stamp);
  CHECK(r.frame.frame.id == 0x680);
  CHECK(r.frame.frame.len == 8);
  CHECK(r.frame.frame.data[1] == 0x22);
  auto t = parse_ok("(1700000000.000100)  can1  1F334455   [2]  AB CD");
  CHECK(t.has_stamp);
  CHECK(t.frame.frame.extended());
  CHECK(t.frame.frame.len == 2);
  auto rtr = parse_ok("  can0  123   [2]  remote request");
  CHECK(rtr.frame.frame.remote());
  CHECK(rtr.frame.frame.len == 2);
  auto fd = parse_ok("  can0  123  [12]  00 11 22 33 44 55 66 77 88 99 AA BB");
  CHECK(fd.frame.frame.fd());
  CHECK(fd.frame.frame.len == 12);
}

TEST_CASE("Malformed lines say what is wrong and where") {
  const struct {
    const char* line;
    const char* reason_part;
  } cases[] = {
      {"(1436509052.249713 can0 123#00", "timestamp"},
      {"(abc) can0 123#00", "timestamp"},
      {"(1.000000)", "interface"},
      {"(1.000000) can0", "frame"},
      {"(1.000000) can0 12#00", "3 (11-bit) or 8 (29-bit)"},
      {"(1.000000) can0 800#00", "3 (11-bit) or 8 (29-bit)"},
      {"(1.000000) can0 123456789#00", "3 (11-bit) or 8 (29-bit)"},
      {"(1.000000) can0 123#0", "odd number"},
      {"(1.000000) can0 123#0G", "odd number"},
      {"(1.000000) can0 123#001122334455667788", "more than 8"},
      {"(1.000000) can0 123##", "flags"},
      {"(1.000000) can0 123##1001122334455667788", "CAN FD data length"},
      {"(1.000000) can0 123#00 X", "direction"},
      {"(1.000000) can0 123#00 R extra", "unexpected text"},
      {"  can0  680   [9]  00", "CAN FD data length"},
      {"  can0  680   [8]  00 11", "fewer data bytes"},
      {"  can0  680   8  00", "[len]"},
  };
  for (const auto& c : cases) {
    INFO(c.line);
    const CandumpParse p = parse(c.line);
    CHECK(p.kind == CandumpLineKind::Malformed);
    CHECK(std::string(p.reason).find(c.reason_part) != std::string::npos);
    CHECK(p.column >= 1);
  }
}

TEST_CASE("Mutated and random lines never crash the parser and never yield impossible frames") {
  const std::string seeds[] = {
      "(1436509052.249713) can0 123#DEADBEEF", "(1.000000) vcan1 1F334455##5" + std::string(128, 'C'),
      "(1.000000) can0 20000004#0004000000000000", "  can0  680   [8]  03 22 01 00 00 00 00 00",
      "(1.000000) can0 123#R8 T"};
  const std::string alphabet = "0123456789ABCDEFabcdefRT#()[]._ \t\r.-xX\xff";
  std::mt19937 rng(1234);
  int frames = 0, malformed = 0;
  for (int iter = 0; iter < 20000; ++iter) {
    std::string line = seeds[rng() % std::size(seeds)];
    const int edits = 1 + static_cast<int>(rng() % 4);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = line.empty() ? 0 : rng() % line.size();
      switch (rng() % 4) {
        case 0: if (!line.empty()) line[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: if (!line.empty()) line.erase(at, 1 + rng() % 3); break;
        case 2: line.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
        case 3: line = line.substr(0, at); break;
      }
    }
    CandumpRecord r;
    const CandumpParse p = parse_candump_line(line, r);
    if (p.kind == CandumpLineKind::Frame) {
      ++frames;
      const auto& f = r.frame.frame;
      REQUIRE(f.len <= (f.fd() ? 64 : 8));
      REQUIRE(f.id <= (f.extended() || f.error() ? 0x1FFFFFFFu : 0x7FFu));
      REQUIRE(impossible_frame_reason(f) == nullptr);
    } else if (p.kind == CandumpLineKind::Malformed) {
      ++malformed;
      REQUIRE(p.reason[0] != '\0');
      REQUIRE(p.column >= 1);
      REQUIRE(static_cast<std::size_t>(p.column) <= line.size() + 1);
    }
  }
  CHECK(frames > 100);     // some mutations stay valid
  CHECK(malformed > 1000); // most do not
}

TEST_CASE("The reader skips malformed lines with their line numbers and keeps going") {
  const std::string text =
      "# header comment\r\n"
      "(1.000000) can0 123#00\r\n"
      "\r\n"
      "garbage line\r\n"
      "(1.000100) can0 124#0011\r\n"
      "(1.000200) can0 125#001\n"
      "(1.000300) can0 126#";  // no final newline
  auto reader = CandumpReader::from_memory(text);
  std::vector<std::uint64_t> reported;
  reader.on_error([&](const CandumpLineError& e) { reported.push_back(e.line); });
  CandumpRecord r;
  std::vector<std::uint32_t> ids;
  while (reader.next(r)) ids.push_back(r.frame.frame.id);
  CHECK(ids == std::vector<std::uint32_t>{0x123, 0x124, 0x126});
  CHECK(reader.lines() == 7);
  CHECK(reader.frames() == 3);
  CHECK(reader.malformed() == 2);
  CHECK(reported == std::vector<std::uint64_t>{4, 6});
  REQUIRE(reader.first_errors().size() == 2);
  CHECK(reader.first_errors()[0].message("x.log").rfind("x.log:4:", 0) == 0);
}

TEST_CASE("Writer and reader round trip every frame kind through a file") {
  epichead::testing::TempDir dir;
  const std::string path = dir / "bus.log";
  std::vector<StampedCanFrame> frames;
  {
    StampedCanFrame a;
    a.stamp_us = 1436509052249713LL;
    a.frame.id = 0x123;
    a.frame.len = 3;
    a.frame.data[0] = 0xAB;
    a.frame.data[2] = 0x01;
    frames.push_back(a);
    StampedCanFrame b = a;
    b.frame.id = 0x1F334455;
    b.frame.flags = CanFlags::Extended | CanFlags::Remote;
    b.frame.len = 5;
    b.frame.data = {};
    frames.push_back(b);
    StampedCanFrame c = a;
    c.frame.flags = CanFlags::Fd | CanFlags::BitRateSwitch;
    c.frame.len = 48;
    for (int i = 0; i < 48; ++i) c.frame.data[i] = static_cast<std::uint8_t>(i * 5);
    frames.push_back(c);
    StampedCanFrame d = a;
    d.stamp_us = 7;
    d.frame.id = 0x40;
    d.frame.flags = CanFlags::Error;
    d.frame.len = 8;
    frames.push_back(d);
  }
  {
    auto w = CandumpWriter::open(path);
    REQUIRE(w);
    for (const auto& f : frames) REQUIRE(w->write(f, "vcan0", CanDirection::Received));
    CHECK_FALSE(w->write(frames[0], "bad name"));
    REQUIRE(w->close());
  }
  auto reader = CandumpReader::open(path);
  REQUIRE(reader);
  CandumpRecord r;
  std::size_t i = 0;
  while (reader->next(r)) {
    REQUIRE(i < frames.size());
    const auto& want = frames[i++];
    CHECK(r.frame.stamp_us == want.stamp_us);
    CHECK(r.iface == "vcan0");
    CHECK(r.direction == CanDirection::Received);
    CHECK(r.frame.frame.id == want.frame.id);
    CHECK(r.frame.frame.flags == want.frame.flags);
    CHECK(r.frame.frame.len == want.frame.len);
    CHECK(r.frame.frame.data == want.frame.data);
  }
  CHECK(i == frames.size());
  CHECK(reader->malformed() == 0);
  CHECK_FALSE(CandumpReader::open(dir / "missing.log"));
}

TEST_CASE("The reader streams a file larger than its buffer and survives an over-long line") {
  epichead::testing::TempDir dir;
  const std::string path = dir / "big.log";
  const int n = 60000;  // ~2.4 MB: more than two buffer refills
  {
    auto w = CandumpWriter::open(path);
    REQUIRE(w);
    StampedCanFrame f;
    f.frame.id = 0x110;
    f.frame.len = 8;
    for (int i = 0; i < n; ++i) {
      f.stamp_us = 1'000'000LL + i * 1000;
      f.frame.data[0] = static_cast<std::uint8_t>(i);
      REQUIRE(w->write(f, "can0"));
    }
    REQUIRE(w->close());
  }
  {
    std::FILE* f = std::fopen(path.c_str(), "ab");
    REQUIRE(f);
    const std::string junk(10000, 'x');
    std::fprintf(f, "%s\n(9.000000) can0 7FF#01\n", junk.c_str());
    std::fclose(f);
  }
  auto reader = CandumpReader::open(path);
  REQUIRE(reader);
  CandumpRecord r;
  int count = 0;
  std::int64_t last = 0;
  bool ordered = true;
  while (reader->next(r)) {
    if (count < n) {
      ordered = ordered && r.frame.stamp_us > last && r.frame.frame.data[0] == static_cast<std::uint8_t>(count);
      last = r.frame.stamp_us;
    }
    ++count;
  }
  CHECK(ordered);
  CHECK(count == n + 1);
  CHECK(reader->malformed() == 1);
  CHECK(reader->first_errors().at(0).line == static_cast<std::uint64_t>(n + 1));
  CHECK(r.frame.frame.id == 0x7FF);
}
