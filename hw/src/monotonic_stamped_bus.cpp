#include "epichead/hw/monotonic_stamped_bus.h"

#include "epichead/hw/clock.h"

#include <time.h>

namespace epichead::hw {

namespace {

std::int64_t ns(const timespec& ts) { return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec; }

constexpr std::int64_t kRemeasureNs = 1'000'000'000;

}  // namespace

CanReceive MonotonicStampedBus::receive(StampedCanFrame& out, double timeout_s) {
  const CanReceive r = bus_.receive(out, timeout_s);
  if (r == CanReceive::Frame) out.stamp_us -= measure_offset_us();
  return r;
}

std::int64_t MonotonicStampedBus::measure_offset_us() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  if (measured_ && ns(now) - measured_at_ns_ < kRemeasureNs) return offset_us_;
  const ClockPair pair = read_clock_pair();
  measured_ = true;
  measured_at_ns_ = ns(now);
  offset_us_ = pair.unix_us - pair.monotonic_us;
  return offset_us_;
}

}  // namespace epichead::hw
