#include <time.h>

#include "epichead/hw/clock.h"
#include "epichead/hw/fake_clock.h"

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

void FakeClock::set(double t_s) {
  double current = t_s_.load(std::memory_order_acquire);
  while (t_s > current && !t_s_.compare_exchange_weak(current, t_s, std::memory_order_acq_rel)) {
  }
}

}  // namespace epichead::hw
