#include <catch2/catch.hpp>

#include <time.h>

#include "epichead/hw/clock.h"
#include "epichead/hw/fake_clock.h"

using namespace epichead::hw;

TEST_CASE("the fake clock moves only forward, by set or advance", "[hw][clock]") {
  FakeClock clock(5.0);
  CHECK(clock.now_s() == 5.0);
  clock.advance(0.25);
  CHECK(clock.now_s() == 5.25);
  clock.set(7.0);
  CHECK(clock.now_s() == 7.0);
  clock.set(6.0);  // earlier: ignored
  CHECK(clock.now_s() == 7.0);
  clock.advance(-1.0);
  CHECK(clock.now_s() == 7.0);
}

TEST_CASE("the monotonic clock reads CLOCK_MONOTONIC, the time base of V4L2 and GPIO stamps", "[hw][clock]") {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  const double before_s = static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
  const double t_s = monotonic_clock().now_s();
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  const double after_s = static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
  CHECK(t_s >= before_s);
  CHECK(t_s <= after_s);
  CHECK(monotonic_clock().now_s() >= t_s);
}
