#include "epichead/hw/monotonic_stamped_bus.h"

#include <time.h>

#include <limits>

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
  // The wall clock read between two monotonic reads, against their midpoint; of three tries the
  // tightest, so a preemption between the reads (a loaded machine, a VM) does not skew it.
  std::int64_t best_width = std::numeric_limits<std::int64_t>::max(), offset_ns = 0;
  for (int i = 0; i < 3; ++i) {
    timespec before{}, wall{}, after{};
    clock_gettime(CLOCK_MONOTONIC, &before);
    clock_gettime(CLOCK_REALTIME, &wall);
    clock_gettime(CLOCK_MONOTONIC, &after);
    if (ns(after) - ns(before) < best_width) {
      best_width = ns(after) - ns(before);
      offset_ns = ns(wall) - (ns(before) + ns(after)) / 2;
    }
  }
  measured_ = true;
  measured_at_ns_ = ns(now);
  offset_us_ = offset_ns / 1000;
  return offset_us_;
}

}  // namespace epichead::hw
