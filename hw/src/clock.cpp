#include <time.h>

#include "epichead/hw/clock.h"
#include "epichead/hw/fake_clock.h"

#include <limits>

namespace epichead::hw {

double MonotonicClock::now_s() const {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

Clock& monotonic_clock() {
  static MonotonicClock clock;
  return clock;
}

namespace {

std::int64_t ns(const timespec& ts) { return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec; }

}  // namespace

ClockPair read_clock_pair() {
  std::int64_t best_width_ns = std::numeric_limits<std::int64_t>::max();
  ClockPair best;
  for (int i = 0; i < 3; ++i) {
    timespec before{}, wall{}, after{};
    ::clock_gettime(CLOCK_MONOTONIC, &before);
    ::clock_gettime(CLOCK_REALTIME, &wall);
    ::clock_gettime(CLOCK_MONOTONIC, &after);
    if (ns(after) - ns(before) < best_width_ns) {
      best_width_ns = ns(after) - ns(before);
      best = {(ns(before) + ns(after)) / 2 / 1000, ns(wall) / 1000};
    }
  }
  return best;
}

void FakeClock::set(double t_s) {
  double current = t_s_.load(std::memory_order_acquire);
  while (t_s > current && !t_s_.compare_exchange_weak(current, t_s, std::memory_order_acq_rel)) {
  }
}

}  // namespace epichead::hw
