#pragma once
// A receive deadline for poll(): timeout_s 0 means "do not wait", negative means "forever".
#include <cmath>
#include <limits>

#include "epichead/hw/clock.h"

namespace epichead::hw {

class Deadline {
 public:
  Deadline(const Clock& clock, double timeout_s)
      : clock_(clock), forever_(timeout_s < 0), end_s_(clock.now_s() + (timeout_s > 0 ? timeout_s : 0)) {}
  // Milliseconds for poll(), rounded up so a wait does not end just before the deadline.
  int remaining_ms() const {
    if (forever_) return -1;
    const double left_ms = std::ceil((end_s_ - clock_.now_s()) * 1e3);
    if (left_ms <= 0) return 0;
    return left_ms > std::numeric_limits<int>::max() ? std::numeric_limits<int>::max() : static_cast<int>(left_ms);
  }
  bool expired() const { return !forever_ && clock_.now_s() >= end_s_; }
  bool forever() const { return forever_; }
  double end_s() const { return end_s_; }

 private:
  const Clock& clock_;
  bool forever_;
  double end_s_;
};

}  // namespace epichead::hw
