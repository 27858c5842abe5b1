#pragma once
// The candump log's time base. candump, and the SocketCAN receive stamps (SO_TIMESTAMP) it
// prints, stamp frames on the wall clock: seconds since the Unix epoch. The onboard loop stamps
// on its own monotonic clock (hw/clock.h; the simulator's time in sim-run). The recorder writes
// the loop's stamps mapped through one (monotonic, wall) pair, so its log merges with a candump
// taken beside it; the diagnostics stream keeps the monotonic stamps and records the pair.
//
// Why one pair and not a wall-clock reading per frame: on Linux both clocks run at the same
// NTP-disciplined rate (adjtime slews both), so their difference changes only when the wall clock
// is stepped (NTP's first fix on a robot without a battery-backed clock, `date -s`). A reading per
// frame would also reorder frames a microsecond apart by its jitter, and put clock reads on the
// control thread. The recorder's writer re-reads the pair once a second of log time (update()):
// a step that moves the log forward is followed, so the log agrees with candump again after NTP's
// first fix; one that would move it back is not (the log would run backwards, and a reader sorts
// by time), only reported: the log stays on its mapping, off by the step.
#include <cstdint>

#include "epichead/hw/clock.h"

namespace epichead::head {

// Where simulated time 0 lands on the Unix epoch in a simulated run's candump log:
// 2024-01-01T00:00:00Z. A fixed date, so that the same seed writes the same log.
constexpr std::int64_t kSimulatedLogEpochUnix_us = 1'704'067'200'000'000;

class LogClock {
 public:
  // A change of the clocks' difference below this is the reading's jitter, not a step.
  static constexpr std::int64_t kStepThreshold_us = 1000;
  enum class Update { Same, StepFollowed, StepNotFollowed };

  explicit LogClock(hw::ClockPair start) : pair_(start), seen_offset_us_(start.unix_us - start.monotonic_us) {}
  // A loop stamp on the wall clock.
  std::int64_t unix_us(std::int64_t monotonic_us) const { return monotonic_us - pair_.monotonic_us + pair_.unix_us; }
  // A fresh reading of both clocks. A step of the wall clock (kStepThreshold_us or more since the
  // last reading) is followed when the mapping then moves forward, else only reported (see above);
  // a step is reported once. last_step_us() is the last step's size, followed or not.
  Update update(hw::ClockPair now);
  hw::ClockPair pair() const { return pair_; }  // the mapping in use
  std::int64_t last_step_us() const { return last_step_us_; }

 private:
  hw::ClockPair pair_;
  std::int64_t seen_offset_us_;  // wall minus monotonic at the last step (or the start)
  std::int64_t last_step_us_ = 0;
};

}  // namespace epichead::head
