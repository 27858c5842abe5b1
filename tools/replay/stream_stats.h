#pragma once
// Timing of one stream of frames (one CAN id, or one message type): count, rate, gaps between
// consecutive frames, jitter (|gap - nominal period|, the nominal period being the median of
// the first 16 gaps), time on the bus, and optionally a rolling counter's losses/duplicates.
#include <cstdint>
#include <vector>

#include "replay/gap_stats.h"

namespace epichead::tools::replay {

class StreamStats {
 public:
  // A frame seen at stamp_us (has_stamp false: counted, no timing), taking bus_s on the bus.
  void add(std::int64_t stamp_us, bool has_stamp, double bus_s);

  std::uint64_t count() const { return count_; }
  bool timed() const { return timed_ >= 2; }
  double first_s() const { return first_us_ * 1e-6; }
  double last_s() const { return last_us_ * 1e-6; }
  double rate_hz() const;  // (n - 1) / span; 0 when not timed
  double nominal_period_us() const;
  double bus_s() const { return bus_s_; }
  std::uint64_t backwards() const { return backwards_; }  // stamps earlier than the previous one
  const GapStats& gaps_us() const { return gaps_; }
  const GapStats& jitter_us() const { return jitter_; }

  // The last gap added (for counter-wrap estimates), -1 when none.
  double last_gap_us() const { return last_gap_us_; }

 private:
  std::uint64_t count_ = 0, timed_ = 0, backwards_ = 0;
  std::int64_t first_us_ = 0, last_us_ = 0;
  double bus_s_ = 0, last_gap_us_ = -1;
  GapStats gaps_, jitter_;
  std::vector<double> first_gaps_;  // until the nominal period is fixed
  double nominal_us_ = -1;
};

// Losses and duplicates of a rolling counter modulo `modulo`. A gap of more than a whole
// counter cycle is recognised from the time gap and the nominal period.
class CounterTracker {
 public:
  explicit CounterTracker(int modulo = 16) : modulo_(modulo) {}
  void add(int counter, double gap_us, double nominal_us);
  std::uint64_t lost() const { return lost_; }
  std::uint64_t duplicates() const { return duplicates_; }

 private:
  int modulo_;
  int last_ = -1;
  std::uint64_t lost_ = 0, duplicates_ = 0;
};

}  // namespace epichead::tools::replay
