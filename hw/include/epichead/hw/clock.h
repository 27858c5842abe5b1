#pragma once
// The program's clock as a port: monotonic seconds (`t_s`, as in vision/ and sim/). The robot
// reads CLOCK_MONOTONIC; tests and the simulator set the time themselves, so time-driven logic
// (reconnect back-off, receive stamps) runs the same code in both.
#include <cstdint>

namespace epichead::hw {

class Clock {
 public:
  virtual ~Clock() = default;
  // Seconds on a monotonic clock; never goes backwards.
  virtual double now_s() const = 0;
};

// CLOCK_MONOTONIC in seconds: the clock V4L2 buffer stamps and GPIO edge stamps use too.
class MonotonicClock final : public Clock {
 public:
  double now_s() const override;
};

// The one process-wide MonotonicClock, the drivers' default.
Clock& monotonic_clock();

// One moment read on CLOCK_MONOTONIC and on the wall clock (CLOCK_REALTIME, microseconds since
// the Unix epoch: what SocketCAN's SO_TIMESTAMP and candump use).
struct ClockPair {
  std::int64_t monotonic_us = 0, unix_us = 0;
};

// Reads both clocks: the wall clock between two monotonic reads, against their midpoint, the
// tightest of three tries, so a preemption between the reads (a loaded machine, a VM) does not
// skew it. Six clock_gettime calls (vDSO, no system call): still no work for a 1 kHz loop's tick.
ClockPair read_clock_pair();

}  // namespace epichead::hw
