// The candump writer and reader agree: every frame a bus can carry is written within the line
// buffer and reads back as the same frame.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "epichead/firmware_iface/candump_line.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/candump_writer.h"

using namespace epichead::firmware_iface;

namespace {

// A 64-byte CAN FD frame with a 29-bit id, both FD flags and every byte 0xFF.
StampedCanFrame longest_fd_frame(std::int64_t stamp_us) {
  StampedCanFrame s;
  s.stamp_us = stamp_us;
  s.frame.id = 0x1FFFFFFF;
  s.frame.flags = CanFlags::Extended | CanFlags::Fd | CanFlags::BitRateSwitch | CanFlags::ErrorStateIndicator;
  s.frame.len = 64;
  s.frame.data.fill(0xFF);
  return s;
}

}  // namespace

TEST_CASE("kCandumpMaxLine holds the longest line the format allows, and no more") {
  // The buffer is exactly kCandumpMaxLine bytes on the heap, so ASan sees any overflow.
  const std::string iface(kCandumpMaxIface, 'x');
  for (const std::int64_t stamp_us : {INT64_MIN, INT64_MAX, std::int64_t{0}, std::int64_t{999'999'999'999'999'999}}) {
    std::vector<char> buf(kCandumpMaxLine);
    const std::size_t n = format_candump_line(longest_fd_frame(stamp_us), iface, buf.data(), CanDirection::Transmitted);
    INFO(std::string(buf.data(), n));
    CHECK(n <= kCandumpMaxLine);
    if (stamp_us == INT64_MIN) CHECK(n == kCandumpMaxLine);  // the bound is the longest line
  }
}

TEST_CASE("The writer records the longest frame the bus can carry and the reader reads it back") {
  epichead::testing::TempDir dir;
  const std::string path = dir / "long.log";
  const std::string iface(kCandumpMaxIface, 'c');
  const StampedCanFrame want = longest_fd_frame(999'999'999'999'999'999);  // the largest stamp a log holds
  {
    auto w = CandumpWriter::open(path);
    REQUIRE(w);
    REQUIRE(w->write(want, iface, CanDirection::Received));
    const auto too_long = w->write(want, iface + "x");
    REQUIRE_FALSE(too_long);
    CHECK(too_long.error().find("longer than 15") != std::string::npos);
    REQUIRE(w->close());
  }
  auto reader = CandumpReader::open(path);
  REQUIRE(reader);
  CandumpRecord r;
  REQUIRE(reader->next(r));
  CHECK(r.frame.stamp_us == want.stamp_us);
  CHECK(r.iface == iface);
  CHECK(r.direction == CanDirection::Received);
  CHECK(r.frame.frame.id == want.frame.id);
  CHECK(r.frame.frame.flags == want.frame.flags);
  CHECK(r.frame.frame.len == 64);
  CHECK(r.frame.frame.data == want.frame.data);
  CHECK_FALSE(reader->next(r));
  CHECK(reader->malformed() == 0);
}

TEST_CASE("impossible_frame_reason names the frames no bus carries") {
  CanFrame f;
  f.id = 0x123;
  f.len = 2;
  CHECK(impossible_frame_reason(f) == nullptr);
  const struct {
    CanFlags flags;
    std::uint32_t id;
    std::uint8_t len;
    const char* reason_part;
  } cases[] = {
      {CanFlags::Fd | CanFlags::Remote, 0x123, 0, "CAN FD has no remote frames"},
      {CanFlags::Error | CanFlags::Remote, 0x4, 0, "error frame cannot be a remote frame"},
      {CanFlags::Error | CanFlags::Fd, 0x4, 8, "error frame cannot be a CAN FD frame"},
      {CanFlags::Error | CanFlags::Extended, 0x4, 8, "error frame has no 11/29-bit id format"},
      {CanFlags::Error, 0x4, 9, "at most 8 data bytes"},
      {CanFlags::None, 0x800, 0, "wider than 11 bits"},
      {CanFlags::Extended, 0x20000000, 0, "wider than 29 bits"},
      {CanFlags::BitRateSwitch, 0x123, 1, "only on CAN FD"},
      {CanFlags::None, 0x123, 9, "at most 8 data bytes"},
      {CanFlags::Remote, 0x123, 9, "at most 8 data bytes"},
      {CanFlags::Fd, 0x123, 13, "CAN FD data length"},
  };
  for (const auto& c : cases) {
    CanFrame g;
    g.flags = c.flags;
    g.id = c.id;
    g.len = c.len;
    const char* why = impossible_frame_reason(g);
    INFO(c.reason_part);
    REQUIRE(why != nullptr);
    CHECK(std::string(why).find(c.reason_part) != std::string::npos);
  }
}

TEST_CASE("The reader rejects the impossible frames the human-readable form could express") {
  const struct {
    const char* line;
    const char* reason_part;
  } cases[] = {
      {"  can0  123  [12]  remote request", "CAN FD has no remote frames"},
      {"  can0  123  [08]  remote request", "CAN FD has no remote frames"},
      {"  can0  20000004   [8]  remote request", "error frame cannot be a remote frame"},
      {"  can0  20000004  [08]  00 04 00 00 00 00 00 00", "error frame cannot be a CAN FD frame"},
      {"(1.000000) can0 20000004##10004000000000000", "error frame cannot be a CAN FD frame"},
      {"(1.000000) can0 123#R", nullptr},
      {"(1.000000) can0 123##0", nullptr},
  };
  for (const auto& c : cases) {
    INFO(c.line);
    CandumpRecord r;
    const CandumpParse p = parse_candump_line(c.line, r);
    if (!c.reason_part) {
      CHECK(p.kind == CandumpLineKind::Frame);
      continue;
    }
    REQUIRE(p.kind == CandumpLineKind::Malformed);
    CHECK(std::string(p.reason).find(c.reason_part) != std::string::npos);
    CHECK(p.column >= 1);
    CHECK(static_cast<std::size_t>(p.column) <= std::string(c.line).size());
  }
}

TEST_CASE("Error columns stay within the line, at most one past its last character") {
  // "123#R8_" used to report a column two past the end.
  for (const std::string line : {"(1.000000) can0 123#R8_", "(1.000000) can0 123#R_", "(1.000000) can0 123#R4_C",
                                 "(1.000000) can0 123#R8_5", "(1.000000) can0 123#0", "(1.000000) can0"}) {
    INFO(line);
    CandumpRecord r;
    const CandumpParse p = parse_candump_line(line, r);
    REQUIRE(p.kind == CandumpLineKind::Malformed);
    CHECK(p.column >= 1);
    CHECK(static_cast<std::size_t>(p.column) <= line.size() + 1);
  }
  CandumpRecord r;
  REQUIRE(parse_candump_line("(1.000000) can0 123#R8_C", r).kind == CandumpLineKind::Frame);
  CHECK(r.frame.frame.len == 8);
}

TEST_CASE("The writer refuses impossible frames and stamps a log cannot hold, with a clear message") {
  epichead::testing::TempDir dir;
  auto w = CandumpWriter::open(dir / "bus.log");
  REQUIRE(w);
  StampedCanFrame s;
  s.stamp_us = 1'000'000;
  s.frame.id = 0x123;
  s.frame.flags = CanFlags::Fd | CanFlags::Remote;
  auto fd_remote = w->write(s, "can0");
  REQUIRE_FALSE(fd_remote);
  CHECK(fd_remote.error().find("bus.log: cannot record CAN id 0x123: CAN FD has no remote frames") != std::string::npos);
  s.frame.flags = CanFlags::Error | CanFlags::Remote;
  REQUIRE_FALSE(w->write(s, "can0"));
  s.frame.flags = CanFlags::None;
  s.stamp_us = -1;
  auto negative = w->write(s, "can0");
  REQUIRE_FALSE(negative);
  CHECK(negative.error().find("stamped -1 us") != std::string::npos);
  s.stamp_us = 1'000'000'000'000LL * 1'000'000;
  REQUIRE_FALSE(w->write(s, "can0"));
  CHECK(w->frames() == 0);
  REQUIRE(w->close());
}

TEST_CASE("Every possible frame kind written by the writer reads back as the same frame") {
  epichead::testing::TempDir dir;
  const std::string path = dir / "kinds.log";
  std::vector<StampedCanFrame> frames;
  const CanFlags kinds[] = {CanFlags::None,
                            CanFlags::Extended,
                            CanFlags::Remote,
                            CanFlags::Extended | CanFlags::Remote,
                            CanFlags::Error,
                            CanFlags::Fd,
                            CanFlags::Fd | CanFlags::Extended | CanFlags::BitRateSwitch,
                            CanFlags::Fd | CanFlags::ErrorStateIndicator};
  for (const CanFlags flags : kinds) {
    for (const std::uint8_t len : {0, 1, 8, 12, 64}) {
      StampedCanFrame s;
      s.stamp_us = 1436509052249713LL + static_cast<std::int64_t>(frames.size());
      s.frame.flags = flags;
      s.frame.id = s.frame.extended() ? 0x1ABCDEF0u : 0x5A5u;
      s.frame.len = len;
      if (!s.frame.remote())
        for (int i = 0; i < len; ++i) s.frame.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i * 7 + 1);
      if (impossible_frame_reason(s.frame)) continue;
      frames.push_back(s);
    }
  }
  {
    auto w = CandumpWriter::open(path);
    REQUIRE(w);
    for (const auto& f : frames) REQUIRE(w->write(f, "can0"));
    REQUIRE(w->close());
  }
  auto reader = CandumpReader::open(path);
  REQUIRE(reader);
  CandumpRecord r;
  std::size_t i = 0;
  while (reader->next(r)) {
    REQUIRE(i < frames.size());
    const auto& want = frames[i++].frame;
    INFO("frame " << i);
    CHECK(r.frame.frame.flags == want.flags);
    CHECK(r.frame.frame.id == want.id);
    CHECK(r.frame.frame.len == want.len);
    CHECK(r.frame.frame.data == want.data);
  }
  CHECK(i == frames.size());
  CHECK(reader->malformed() == 0);
}
