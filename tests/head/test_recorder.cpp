// The onboard loop's recorder (head/src/recorder.h): with its writer thread it writes exactly what
// the inline recorder writes (the candump log and the diagnostics lines, in order), counts what
// it had to drop, and close() writes everything queued before it returns. The candump log is on
// the wall clock of a fake clock pair; the diagnostics stream records the pair and its steps.
#include <catch2/catch.hpp>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "recorder.h"

using namespace epichead;
namespace fw = epichead::firmware_iface;

namespace {

// The robot 1 s after boot, its wall clock at 2026-12-04T05:00:00Z.
constexpr std::int64_t kBoot_us = 1'000'000, kWall_us = 1'796'360'400'000'000;
hw::ClockPair fixed_pair() { return {kBoot_us, kWall_us}; }

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// 5000 frames and 200 lines through a recorder in `mode`; returns the two files' contents.
std::pair<std::string, std::string> record(head::Recorder::Mode mode, head::RecorderCounters& counters) {
  testing::TempDir dir("recorder");
  auto rec = head::Recorder::open(dir / "bus.log", "can0", dir / "diag.jsonl", mode, fixed_pair);
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
  CHECK(inline_counters.lines_written == 201);  // the clock map and 200 lines
  CHECK(inline_counters.lines_dropped == 1);
  // 5000 frames fit the thread's queue, so nothing is dropped and the files are the same.
  CHECK(thread_counters.frames_dropped == 0);
  CHECK(thread_counters.frames_logged == 5000);
  CHECK(thread_counters.lines_dropped == 1);
  CHECK(thread_counters.frame_queue_high_water >= 1);
  CHECK(thread_log == inline_log);
  CHECK(thread_diag == inline_diag);
  CHECK(inline_log.find("can0 100#") != std::string::npos);
  // Frame 0 was stamped at the pair's monotonic time: it is written at the pair's wall time.
  CHECK(inline_log.rfind("(1796360400.000000) can0 100#", 0) == 0);
  CHECK(inline_diag.rfind("{\"t_s\":1.000000,\"clock_map\":{\"monotonic_s\":1.000000,\"unix_s\":1796360400.000000}}\n", 0) == 0);
}

TEST_CASE("recorder: the log follows a step forward of the wall clock, not one back, and says so in the diagnostics",
          "[head][recorder]") {
  testing::TempDir dir("recorder_steps");
  // The fake pair: the wall clock runs with the monotonic one; the test steps it.
  std::int64_t wall_minus_mono_us = kWall_us - kBoot_us;
  std::int64_t mono_now_us = kBoot_us;
  auto pair = [&] { return hw::ClockPair{mono_now_us, mono_now_us + wall_minus_mono_us}; };
  auto rec = head::Recorder::open(dir / "bus.log", "can0", dir / "diag.jsonl", head::Recorder::Mode::Inline, pair);
  REQUIRE(rec);
  auto send = [&](std::int64_t stamp_us) {
    mono_now_us = stamp_us;
    fw::StampedCanFrame f;
    f.stamp_us = stamp_us;
    f.frame.id = 0x100;
    f.frame.len = 8;
    (*rec)->frame(f, fw::CanDirection::Transmitted);
  };
  for (int i = 0; i < 1500; ++i) send(kBoot_us + i * 1000);  // 1.5 s at 1 kHz
  wall_minus_mono_us += 3'600'000'000;                        // NTP's first fix: 1 h ahead
  for (int i = 1500; i < 3000; ++i) send(kBoot_us + i * 1000);
  wall_minus_mono_us -= 5'000'000;                            // then 5 s back
  for (int i = 3000; i < 4500; ++i) send(kBoot_us + i * 1000);
  REQUIRE((*rec)->close());

  const std::string log = slurp(dir / "bus.log");
  auto reader = fw::CandumpReader::from_memory(log);
  fw::CandumpRecord r;
  std::vector<std::int64_t> stamps;
  while (reader.next(r)) stamps.push_back(r.frame.stamp_us);
  REQUIRE(stamps.size() == 4500);
  CHECK(stamps[0] == kWall_us);
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    INFO("frame " << i);
    REQUIRE(stamps[i] > stamps[i - 1]);  // never backwards
  }
  // The step is seen at the first reading after it (once a second of log time: frame 2000) and
  // followed from there on; the step back (seen at frame 3000) is not.
  CHECK(stamps[1999] == kWall_us + 1'999'000);
  CHECK(stamps[2000] == kWall_us + 2'000'000 + 3'600'000'000);
  CHECK(stamps[4499] == kWall_us + 4'499'000 + 3'600'000'000);

  std::istringstream diag(slurp(dir / "diag.jsonl"));
  std::vector<std::string> lines;
  for (std::string line; std::getline(diag, line);) lines.push_back(line);
  REQUIRE(lines.size() == 3);
  CHECK(lines[0] == "{\"t_s\":1.000000,\"clock_map\":{\"monotonic_s\":1.000000,\"unix_s\":1796360400.000000}}");
  CHECK(lines[1] == "{\"t_s\":3.000000,\"clock_map\":{\"monotonic_s\":3.000000,\"unix_s\":1796364002.000000},"
                    "\"wall_clock_step_s\":3600.000000,\"step_followed\":true}");
  CHECK(lines[2] == "{\"t_s\":4.000000,\"clock_map\":{\"monotonic_s\":3.000000,\"unix_s\":1796364002.000000},"
                    "\"wall_clock_step_s\":-5.000000,\"step_followed\":false}");
}

TEST_CASE("recorder: a path that cannot be written is an error naming it", "[head][recorder]") {
  auto rec = head::Recorder::open("/nonexistent-dir/bus.log", "can0", "", head::Recorder::Mode::Thread, fixed_pair);
  REQUIRE_FALSE(rec);
  CHECK(rec.error().find("/nonexistent-dir/bus.log") != std::string::npos);
}
