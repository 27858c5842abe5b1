// The candump log's clock (head/log_clock.h): the loop's monotonic stamps mapped onto the Unix
// epoch through one (monotonic, wall) pair; a step of the wall clock is followed forward only.
#include <catch2/catch.hpp>

#include "epichead/head/log_clock.h"
#include "epichead/hw/clock.h"

using epichead::head::LogClock;
using epichead::hw::ClockPair;

namespace {
// A robot up for 100 s, its wall clock then at 2026-12-04T05:00:00Z.
constexpr std::int64_t kBoot_us = 100'000'000, kWall_us = 1'796'360'400'000'000;
}  // namespace

TEST_CASE("log clock: a monotonic stamp lands on the wall clock by the pair's offset, microsecond exact",
          "[head][log_clock]") {
  const LogClock clock(ClockPair{kBoot_us, kWall_us});
  CHECK(clock.unix_us(kBoot_us) == kWall_us);
  CHECK(clock.unix_us(kBoot_us + 1) == kWall_us + 1);
  CHECK(clock.unix_us(kBoot_us - 250) == kWall_us - 250);  // a receive stamp just before the pair was read
  CHECK(clock.unix_us(kBoot_us + 3'600'000'000) == kWall_us + 3'600'000'000);
}

TEST_CASE("log clock: a simulated run's time 0 is the fixed epoch 2024-01-01T00:00:00Z", "[head][log_clock]") {
  const LogClock clock(ClockPair{0, epichead::head::kSimulatedLogEpochUnix_us});
  CHECK(epichead::head::kSimulatedLogEpochUnix_us == 1'704'067'200'000'000);
  CHECK(clock.unix_us(0) == 1'704'067'200'000'000);
  CHECK(clock.unix_us(2'500'000) == 1'704'067'202'500'000);
}

TEST_CASE("log clock: reading jitter below the step threshold keeps the mapping", "[head][log_clock]") {
  LogClock clock(ClockPair{kBoot_us, kWall_us});
  CHECK(clock.update(ClockPair{kBoot_us + 1'000'000, kWall_us + 1'000'000 + 3}) == LogClock::Update::Same);
  CHECK(clock.update(ClockPair{kBoot_us + 2'000'000, kWall_us + 2'000'000 - 999}) == LogClock::Update::Same);
  CHECK(clock.unix_us(kBoot_us + 5) == kWall_us + 5);
}

TEST_CASE("log clock: a step forward of the wall clock (NTP's first fix) is followed", "[head][log_clock]") {
  LogClock clock(ClockPair{kBoot_us, kWall_us});
  const ClockPair after{kBoot_us + 10'000'000, kWall_us + 10'000'000 + 7'200'000'000};  // 2 h ahead
  CHECK(clock.update(after) == LogClock::Update::StepFollowed);
  CHECK(clock.last_step_us() == 7'200'000'000);
  CHECK(clock.unix_us(kBoot_us + 10'000'000) == after.unix_us);
  CHECK(clock.update(after) == LogClock::Update::Same);  // reported once
}

TEST_CASE("log clock: a step back is reported once and not followed, so the log never runs backwards",
          "[head][log_clock]") {
  LogClock clock(ClockPair{kBoot_us, kWall_us});
  const std::int64_t before = clock.unix_us(kBoot_us + 10'000'000);
  CHECK(clock.update(ClockPair{kBoot_us + 10'000'000, kWall_us + 10'000'000 - 3'000'000}) ==
        LogClock::Update::StepNotFollowed);
  CHECK(clock.last_step_us() == -3'000'000);
  CHECK(clock.unix_us(kBoot_us + 10'000'000) == before);
  CHECK(clock.update(ClockPair{kBoot_us + 11'000'000, kWall_us + 11'000'000 - 3'000'000}) == LogClock::Update::Same);
  // Stepped forward again by 1 s: still behind the mapping in use, so not followed either.
  CHECK(clock.update(ClockPair{kBoot_us + 12'000'000, kWall_us + 12'000'000 - 2'000'000}) ==
        LogClock::Update::StepNotFollowed);
  CHECK(clock.unix_us(kBoot_us + 12'000'000) == kWall_us + 12'000'000);
  // Past it: followed.
  CHECK(clock.update(ClockPair{kBoot_us + 13'000'000, kWall_us + 13'000'000 + 5'000'000}) ==
        LogClock::Update::StepFollowed);
  CHECK(clock.unix_us(kBoot_us + 13'000'000) == kWall_us + 13'000'000 + 5'000'000);
}

TEST_CASE("log clock: the system's clock pair is on the Unix epoch and the monotonic clock", "[head][log_clock]") {
  const ClockPair a = epichead::hw::read_clock_pair();
  const ClockPair b = epichead::hw::read_clock_pair();
  CHECK(a.unix_us > 1'600'000'000'000'000);  // after 2020
  CHECK(b.monotonic_us >= a.monotonic_us);
  const double mono_now_s = epichead::hw::monotonic_clock().now_s();
  CHECK(static_cast<double>(b.monotonic_us) * 1e-6 <= mono_now_s + 1e-6);
  CHECK(static_cast<double>(b.monotonic_us) * 1e-6 > mono_now_s - 1.0);
}
