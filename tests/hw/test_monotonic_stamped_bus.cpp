// The wall-to-monotonic stamp adapter of epichead run: a frame stamped with the wall clock now
// comes out stamped with the monotonic clock now; sends, stats and timeouts pass through.
#include <catch2/catch.hpp>

#include <time.h>

#include <cstdlib>
#include <deque>

#include "epichead/hw/monotonic_stamped_bus.h"

using namespace epichead::hw;

namespace {

std::int64_t now_us(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
}

// Hands out frames stamped with the wall clock at the moment of receive(), as SocketCAN does.
class WallStampedBus final : public CanBus {
 public:
  std::expected<void, std::string> send(const CanFrame& frame) override {
    sent.push_back(frame);
    return {};
  }
  CanReceive receive(StampedCanFrame& out, double) override {
    if (pending == 0) return CanReceive::Timeout;
    --pending;
    out = {};
    out.frame.id = 0x123;
    out.stamp_us = now_us(CLOCK_REALTIME);
    return CanReceive::Frame;
  }
  CanBusStats stats() const override {
    CanBusStats s;
    s.rx_dropped = 7;
    return s;
  }
  std::string_view last_error() const override { return "none"; }
  int pending = 0;
  std::deque<CanFrame> sent;
};

}  // namespace

TEST_CASE("monotonic stamps: a wall-clock stamp comes out on the monotonic clock", "[hw][can]") {
  WallStampedBus wall;
  MonotonicStampedBus bus(wall);
  wall.pending = 200;
  StampedCanFrame f;
  std::int64_t previous = 0;
  for (int i = 0; i < 200; ++i) {
    const std::int64_t before = now_us(CLOCK_MONOTONIC);
    REQUIRE(bus.receive(f, 0) == CanReceive::Frame);
    const std::int64_t after = now_us(CLOCK_MONOTONIC);
    // Within the call's own span, plus a few ms for a preempted clock read on a loaded machine.
    CHECK(f.stamp_us >= before - 5000);
    CHECK(f.stamp_us <= after + 5000);
    CHECK(f.stamp_us >= previous);  // one offset per second: the stream keeps its order
    previous = f.stamp_us;
  }
  CHECK(std::llabs(bus.wall_minus_monotonic_us() - (now_us(CLOCK_REALTIME) - now_us(CLOCK_MONOTONIC))) < 5000);
}

TEST_CASE("monotonic stamps: sends, timeouts, stats and errors pass through unchanged", "[hw][can]") {
  WallStampedBus wall;
  MonotonicStampedBus bus(wall);
  CanFrame frame;
  frame.id = 0x42;
  REQUIRE(bus.send(frame));
  REQUIRE(wall.sent.size() == 1);
  CHECK(wall.sent.front().id == 0x42);
  StampedCanFrame f;
  f.stamp_us = 99;
  CHECK(bus.receive(f, 0) == CanReceive::Timeout);
  CHECK(f.stamp_us == 99);  // untouched when nothing arrived
  CHECK(bus.stats().rx_dropped == 7);
  CHECK(bus.last_error() == "none");
}
