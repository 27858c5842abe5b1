#include "epichead/head/device_clock_sync.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace epichead::head {

DeviceClockSync::DeviceClockSync(const ClockSyncOptions& options) : options_(options) {
  options_.window = std::clamp(options_.window, 1, static_cast<int>(recent_.size()));
  sent_s_.fill(std::numeric_limits<double>::quiet_NaN());
}

firmware_iface::TimeSyncRequest DeviceClockSync::make_request(double now_s) {
  firmware_iface::TimeSyncRequest r;
  r.sequence = ++sequence_;
  r.controller_stamp_us = static_cast<std::uint64_t>(std::max(0.0, now_s) * 1e6) & firmware_iface::kTimeSyncStampMask;
  sent_s_[r.sequence] = now_s;
  ++counters_.requests;
  return r;
}

bool DeviceClockSync::on_reply(const firmware_iface::TimeSyncReply& reply, double now_s) {
  const double t0 = sent_s_[reply.sequence];
  sent_s_[reply.sequence] = std::numeric_limits<double>::quiet_NaN();  // a duplicate reply pairs with nothing
  const double round_trip = now_s - t0;
  if (!std::isfinite(t0) || !(round_trip >= 0) || round_trip > options_.max_round_trip_s) {
    ++counters_.rejected;
    return false;
  }
  ++counters_.replies;
  const double mid_us = 0.5 * (t0 + now_s) * 1e6;
  recent_[static_cast<std::size_t>(recent_next_)] = {static_cast<double>(reply.device_stamp_us) - mid_us, round_trip};
  recent_next_ = (recent_next_ + 1) % options_.window;
  recent_count_ = std::min(recent_count_ + 1, options_.window);
  best_ = *std::min_element(recent_.begin(), recent_.begin() + recent_count_,
                            [](const Pair& a, const Pair& b) { return a.round_trip_s < b.round_trip_s; });
  return true;
}

ClockSyncCounters DeviceClockSync::counters() const {
  ClockSyncCounters c = counters_;
  c.round_trip_s = round_trip_s();
  return c;
}

double DeviceClockSync::to_controller_s(std::uint64_t device_us) const {
  return (static_cast<double>(device_us) - best_->offset_us) * 1e-6;
}

std::int64_t DeviceClockSync::device_us_at(double t_s) const {
  return static_cast<std::int64_t>(std::llround(t_s * 1e6 + best_->offset_us));
}

}  // namespace epichead::head
