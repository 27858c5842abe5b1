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

// The longest round trip a sync may accept: the IMU's sample stamps wrap every 65.5 ms and are
// unwrapped against the synced clock, whose error is up to half the round trip.
inline constexpr double kMaxClockSyncRoundTrip_s = 0.06;

struct ClockSyncOptions {
  // Longer round trips say nothing precise: ignored. On CAN a round trip is a millisecond or
  // two; a loaded or emulated machine (the VM test) may need more, up to kMaxClockSyncRoundTrip_s.
  double max_round_trip_s = 0.02;
  // How late after its arrival a reply may be read: the loop reads the bus once per control
  // tick and stamps what it reads with the tick's time, so a reply read at the tick that sent
  // the request shows a round trip of 0.
  double read_resolution_s = 0.001;
  int window = 8;                  // replies the minimum round trip is taken over (1..16)
};

struct ClockSyncCounters {
  std::uint64_t requests = 0, replies = 0;  // requests sent; replies used
  std::uint64_t rejected = 0;               // replies matching no request or with too long a round trip
  double round_trip_s = 0;                  // of the pair in use (0: not synced)
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
  // How far device_us_at() can be from the device's clock: the reply was stamped somewhere
  // within the round trip (read up to read_resolution_s late), and the midpoint is taken
  // (requires synced()).
  double max_error_s() const { return 0.5 * best_->round_trip_s + options_.read_resolution_s; }
  ClockSyncCounters counters() const;

 private:
  struct Pair { double offset_us; double round_trip_s; };
  ClockSyncOptions options_;
  std::uint8_t sequence_ = 0;
  std::array<double, 256> sent_s_{};      // by sequence: when the request went out (NaN: none)
  std::array<Pair, 16> recent_{};
  int recent_count_ = 0, recent_next_ = 0;
  std::optional<Pair> best_;
  ClockSyncCounters counters_;
};

}  // namespace epichead::head
