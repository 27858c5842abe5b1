// The onboard loop's recorder (head/src/recorder.h): with its writer thread it writes exactly what
// the inline recorder writes (the candump log and the diagnostics lines, in order), counts what
// it had to drop, and close() writes everything queued before it returns.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>
#include <string>

#include "common/temp_dir.h"
#include "recorder.h"

using namespace epichead;
namespace fw = epichead::firmware_iface;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// 5000 frames and 200 lines through a recorder in `mode`; returns the two files' contents.
std::pair<std::string, std::string> record(head::Recorder::Mode mode, head::RecorderCounters& counters) {
  testing::TempDir dir("recorder");
  auto rec = head::Recorder::open(dir / "bus.log", "can0", dir / "diag.jsonl", mode);
  REQUIRE(rec);
  for (int i = 0; i < 5000; ++i) {
    fw::StampedCanFrame f;
    f.stamp_us = 1'000'000 + i * 250;
    f.frame.id = static_cast<std::uint32_t>(0x100 + i % 16);
    f.frame.len = 8;
    for (int b = 0; b < 8; ++b) f.frame.data[static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(i + b);
    (*rec)->frame(f, i % 2 ? fw::CanDirection::Received : fw::CanDirection::Transmitted);
    if (i % 25 == 0) (*rec)->line("{\"t_s\":" + std::to_string(i) + "}");
  }
  (*rec)->line(std::string(head::Recorder::kMaxLine + 1, 'x'));  // too long: dropped, counted
  REQUIRE((*rec)->close());
  counters = (*rec)->counters();
  return {slurp(dir / "bus.log"), slurp(dir / "diag.jsonl")};
}

}  // namespace

TEST_CASE("recorder: the writer thread writes what the inline recorder writes, in order", "[head][recorder]") {
  head::RecorderCounters inline_counters, thread_counters;
  const auto [inline_log, inline_diag] = record(head::Recorder::Mode::Inline, inline_counters);
  const auto [thread_log, thread_diag] = record(head::Recorder::Mode::Thread, thread_counters);
  REQUIRE(inline_counters.frames_logged == 5000);
  CHECK(inline_counters.lines_written == 200);
  CHECK(inline_counters.lines_dropped == 1);
  // 5000 frames fit the thread's queue, so nothing is dropped and the files are the same.
  CHECK(thread_counters.frames_dropped == 0);
  CHECK(thread_counters.frames_logged == 5000);
  CHECK(thread_counters.lines_dropped == 1);
  CHECK(thread_counters.frame_queue_high_water >= 1);
  CHECK(thread_log == inline_log);
  CHECK(thread_diag == inline_diag);
  CHECK(inline_log.find("can0 100#") != std::string::npos);
}

TEST_CASE("recorder: a path that cannot be written is an error naming it", "[head][recorder]") {
  auto rec = head::Recorder::open("/nonexistent-dir/bus.log", "can0", "", head::Recorder::Mode::Thread);
  REQUIRE_FALSE(rec);
  CHECK(rec.error().find("/nonexistent-dir/bus.log") != std::string::npos);
}
