#pragma once
// Restores a full device time from a wrapping stamp (the IMU frames' 65.536 ms stamp): each
// new stamp is placed after the previous one, and a hint of elapsed time (the receive or log
// time difference) adds the whole wraps that a long gap hides.
#include <cstdint>
#include <optional>

namespace epichead::firmware_iface {

class StampUnwrapper {
 public:
  explicit StampUnwrapper(std::uint64_t wrap_us) : wrap_us_(wrap_us) {}

  // Seeds the full time, e.g. from a TimeSyncReply's 48-bit device clock.
  void reset(std::uint64_t full_us) { last_ = full_us; }

  // The full device time of a stamp `mod_us` (< wrap). elapsed_hint_us: time since the previous
  // stamp by another clock, negative when unknown. The first stamp starts at mod_us itself.
  std::uint64_t unwrap(std::uint32_t mod_us, std::int64_t elapsed_hint_us = -1) {
    if (!last_) return *(last_ = mod_us);
    const std::uint64_t delta = (mod_us + wrap_us_ - *last_ % wrap_us_) % wrap_us_;
    std::uint64_t wraps = 0;
    if (elapsed_hint_us > static_cast<std::int64_t>(delta))
      wraps = (static_cast<std::uint64_t>(elapsed_hint_us) - delta + wrap_us_ / 2) / wrap_us_;
    return *(last_ = *last_ + delta + wraps * wrap_us_);
  }

 private:
  std::uint64_t wrap_us_;
  std::optional<std::uint64_t> last_;
};

}  // namespace epichead::firmware_iface
