#include "epichead/head/log_clock.h"

namespace epichead::head {

LogClock::Update LogClock::update(hw::ClockPair now) {
  const std::int64_t offset_us = now.unix_us - now.monotonic_us;
  const std::int64_t step_us = offset_us - seen_offset_us_;
  if (step_us > -kStepThreshold_us && step_us < kStepThreshold_us) return Update::Same;
  seen_offset_us_ = offset_us;
  last_step_us_ = step_us;
  if (offset_us <= pair_.unix_us - pair_.monotonic_us) return Update::StepNotFollowed;
  pair_ = now;
  return Update::StepFollowed;
}

}  // namespace epichead::head
