#pragma once
// The offset between one device's clock and the controller's, from time-sync request/reply
// pairs (firmware_iface/time_sync.h): offset = d - (t0 + t1) / 2 for a request sent at t0 and
// answered at t1 with the device's clock d. Of the recent pairs the one with the shortest round
// trip is used (its midpoint is the least disturbed by bus queueing), so one late reply does
// not move the mapping.
#include <array>
#include <cstdint>
#include <optional>

#include "epichead/firmware_iface/time_sync.h"

namespace epichead::head {

struct ClockSyncOptions {
  double max_round_trip_s = 0.02;  // longer round trips say nothing precise: ignored
  int window = 8;                  // replies the minimum round trip is taken over (1..16)
};

class DeviceClockSync {
 public:
  explicit DeviceClockSync(const ClockSyncOptions& options = {});
  // The request to broadcast now (controller clock now_s); remembers it to pair the reply.
  firmware_iface::TimeSyncRequest make_request(double now_s);
  // A reply received at now_s. False when it matches no pending request or its round trip is too long.
  bool on_reply(const firmware_iface::TimeSyncReply& reply, double now_s);
  bool synced() const { return best_.has_value(); }
  // Device microseconds -> controller seconds (requires synced()).
  double to_controller_s(std::uint64_t device_us) const;
  // The device clock (us) at controller time t_s (requires synced()).
  std::int64_t device_us_at(double t_s) const;
  double round_trip_s() const { return best_ ? best_->round_trip_s : 0.0; }
  std::uint64_t replies() const { return replies_; }
  std::uint64_t rejected() const { return rejected_; }

 private:
  struct Pair { double offset_us; double round_trip_s; };
  ClockSyncOptions options_;
  std::uint8_t sequence_ = 0;
  std::array<double, 256> sent_s_{};      // by sequence: when the request went out (NaN: none)
  std::array<Pair, 16> recent_{};
  int recent_count_ = 0, recent_next_ = 0;
  std::optional<Pair> best_;
  std::uint64_t replies_ = 0, rejected_ = 0;
};

}  // namespace epichead::head
