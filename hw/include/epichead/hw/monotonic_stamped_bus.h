#pragma once
// A CanBus that moves the receive stamps of another bus from the wall clock onto the monotonic
// clock. SocketCAN stamps received frames with the kernel's wall clock (as candump does), while
// the onboard loop runs on, and stamps what it sends with, CLOCK_MONOTONIC: a log mixing the two
// spans 1.8e9 s and replays as nonsense (found by the VM test, docs/vm.md). With this adapter the
// recorded log has one time base, the program's.
//
// The offset between the clocks is measured once a second (the tightest of three readings), so
// the stamps of one stream keep their order (a fresh, jittery offset per frame could reorder
// frames a millisecond apart), and a step of the wall clock (NTP) is followed within a second.
#include <cstdint>

#include "epichead/hw/can_bus.h"

namespace epichead::hw {

class MonotonicStampedBus final : public CanBus {
 public:
  explicit MonotonicStampedBus(CanBus& wall_stamped_bus) : bus_(wall_stamped_bus) {}
  std::expected<void, std::string> send(const CanFrame& frame) override { return bus_.send(frame); }
  CanReceive receive(StampedCanFrame& out, double timeout_s) override;
  CanBusStats stats() const override { return bus_.stats(); }
  std::string_view last_error() const override { return bus_.last_error(); }
  // Wall clock minus monotonic clock, microseconds, as last measured (0 before the first frame).
  std::int64_t wall_minus_monotonic_us() const { return offset_us_; }

 private:
  std::int64_t measure_offset_us();
  CanBus& bus_;
  bool measured_ = false;
  std::int64_t measured_at_ns_ = 0, offset_us_ = 0;
};

}  // namespace epichead::hw
