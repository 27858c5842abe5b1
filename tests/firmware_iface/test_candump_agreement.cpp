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
