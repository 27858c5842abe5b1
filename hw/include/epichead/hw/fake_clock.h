#pragma once
// A clock the caller sets: for tests and the simulator's time. Safe to read from other threads.
#include <atomic>

#include "epichead/hw/clock.h"

namespace epichead::hw {

class FakeClock final : public Clock {
 public:
  explicit FakeClock(double start_s = 0.0) : t_s_(start_s) {}
  double now_s() const override { return t_s_.load(std::memory_order_acquire); }
  // Moves the time to t_s; an earlier time is ignored, so the clock stays monotonic.
  void set(double t_s);
  void advance(double dt_s) { set(now_s() + dt_s); }

 private:
  std::atomic<double> t_s_;
};

}  // namespace epichead::hw
