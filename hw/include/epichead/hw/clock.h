#pragma once
// The program's clock as a port: monotonic seconds (`t_s`, as in vision/ and sim/). The robot
// reads CLOCK_MONOTONIC; tests and the simulator set the time themselves, so time-driven logic
// (reconnect back-off, receive stamps) runs the same code in both.
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

}  // namespace epichead::hw
