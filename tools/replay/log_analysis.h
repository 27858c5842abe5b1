#pragma once
// What `epichead replay` learns from a CAN log: per CAN id and per message type of our
// protocol the timing (count, rate, gaps, jitter), counter losses and duplicates, decode
// errors (short frames, out-of-range fields), saturated values, head fault bits, heartbeats,
// DroneCAN RawIMU transfers, bus load; and bounded series for the plots. Constant memory in
// the log's length (a few MB at most: per-id tables, bounded series and timelines).
#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "epichead/firmware_iface/candump_line.h"
#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/dronecan_raw_imu.h"
#include "epichead/firmware_iface/head_state.h"
#include "epichead/firmware_iface/imu_protocol.h"
#include "epichead/firmware_iface/stamp_unwrap.h"
#include "epichead/firmware_iface/wire_error.h"
#include "replay/bounded_series.h"
#include "replay/rate_timeline.h"
#include "replay/stream_stats.h"

namespace epichead::tools::replay {

// One IMU sample from the log in our axes: where the fusion predictor is fed.
struct ImuObservation {
  double t_s = 0;                 // log (receive) time
  std::int64_t device_us = -1;    // device clock, unwrapped; -1 when unknown
  std::array<double, 3> gyro_radps{}, accel_mps2{};
  firmware_iface::ImuProtocol source = firmware_iface::ImuProtocol::Epichead;
};

struct AnalysisOptions {
  double bitrate = 500'000;         // nominal bit rate of the bus
  double data_bitrate = 2'000'000;  // CAN FD data phase (BRS)
  // Which IMU stream feeds the observer and the IMU plot; nullopt: both.
  std::optional<firmware_iface::ImuProtocol> imu_protocol;
  // Called for every complete IMU sample (gyro and accel of one sample) and every decoded head
  // state, in log order: the onboard estimators' replay (onboard_replay.h) is fed from here.
  std::function<void(const ImuObservation&)> imu_observer;
  std::function<void(double t_s, const firmware_iface::HeadState&)> head_state_observer;
};

struct IdStats {
  std::uint32_t id = 0;
  bool extended = false;
  StreamStats timing;
  std::uint64_t bytes = 0;
  std::uint64_t remote = 0, fd = 0;
};

constexpr int kWireErrorKinds = 8;

struct MessageStats {
  StreamStats timing;
  CounterTracker counter{16};
  std::uint64_t decoded = 0;
  std::array<std::uint64_t, kWireErrorKinds> errors{};  // by WireErrorKind
  std::uint64_t saturated_frames = 0;                    // frames with a value at a field limit
  GapStats device_gaps_us;                               // IMU: gaps of the device's own stamps
};

struct HeartbeatInfo {
  std::uint64_t count = 0;
  int last_state = -1;  // NodeState value
  std::string firmware;  // "major.minor.patch" of the last heartbeat
  int protocol_version = -1;
  std::uint64_t protocol_mismatches = 0;  // heartbeats with a protocol version other than ours
  std::uint64_t last_uptime_s = 0;
};

struct FaultInfo {
  std::uint64_t frames_with_bit = 0;  // HeadStatus frames with the bit set
  std::uint64_t raised = 0;           // times it went from clear to set
  double first_t_s = -1;
};

struct DroneCanStats {
  StreamStats timing;  // per completed transfer
  std::uint64_t frames = 0, transfers = 0, errors = 0, timed_out = 0;
  std::map<std::string, std::uint64_t> error_reasons;
  std::map<int, std::uint64_t> per_node;
};

class LogAnalyzer {
 public:
  explicit LogAnalyzer(AnalysisOptions options = {});

  void add(const firmware_iface::CandumpRecord& record);
  void finish();  // closes open counts (DroneCAN timeouts)

  // Results.
  std::uint64_t frames() const { return frames_; }
  std::uint64_t frames_without_stamp() const { return unstamped_; }
  std::uint64_t error_frames() const { return error_frames_; }
  std::uint64_t protocol_frames() const { return protocol_frames_; }  // ours (decoded or rejected)
  std::uint64_t unknown_frames() const { return unknown_frames_; }    // neither ours nor DroneCAN RawIMU
  bool timed() const { return have_stamp_; }
  double first_s() const { return first_us_ * 1e-6; }
  double last_s() const { return last_us_ * 1e-6; }
  double bus_time_s() const { return bus_s_; }
  double bus_load() const;  // bus time / span; NaN when the log has no time span
  const AnalysisOptions& options() const { return options_; }
  std::vector<const IdStats*> ids() const;  // ordered: 11-bit first, then by id
  std::uint64_t unknown_ids() const;        // distinct ids with no frame of ours
  const MessageStats& message(firmware_iface::MessageType type) const {
    return messages_[static_cast<std::size_t>(type)];
  }
  const std::map<int, HeartbeatInfo>& heartbeats() const { return heartbeats_; }
  const std::array<FaultInfo, 16>& faults() const { return faults_; }
  const DroneCanStats& dronecan() const { return dronecan_; }
  std::uint64_t imu_samples() const { return imu_samples_; }
  std::uint64_t ids_over_limit() const { return ids_over_limit_; }

  // Plot series (bounded).
  const RateTimeline& timeline() const { return timeline_; }
  const BoundedSeries<6>& imu_series() const { return imu_series_; }     // gx gy gz ax ay az
  const BoundedSeries<2>& head_command_series() const { return cmd_series_; }  // pan tilt
  const BoundedSeries<2>& head_state_series() const { return state_series_; }
  static constexpr int kTimelineOther = firmware_iface::kMessageTypeCount;       // channel of foreign frames
  static constexpr int kTimelineDroneCan = firmware_iface::kMessageTypeCount + 1;

 private:
  void add_ours(const firmware_iface::CandumpRecord& r, firmware_iface::MessageType type, double bus_s);
  void emit_imu(double t_s);

  AnalysisOptions options_;
  std::uint64_t frames_ = 0, unstamped_ = 0, error_frames_ = 0, protocol_frames_ = 0, unknown_frames_ = 0;
  bool have_stamp_ = false;
  std::int64_t first_us_ = 0, last_us_ = 0;
  double bus_s_ = 0;
  std::map<std::uint64_t, IdStats> ids_;  // key: id | extended << 32
  std::uint64_t ids_over_limit_ = 0;
  std::array<MessageStats, firmware_iface::kMessageTypeCount> messages_{};
  std::map<int, HeartbeatInfo> heartbeats_;
  std::array<FaultInfo, 16> faults_{};
  std::uint16_t last_faults_ = 0;
  DroneCanStats dronecan_;
  firmware_iface::DroneCanRawImuDecoder dronecan_decoder_;
  firmware_iface::StampUnwrapper gyro_clock_{65536}, accel_clock_{65536};
  std::int64_t last_gyro_log_us_ = -1, last_accel_log_us_ = -1;
  std::uint64_t last_gyro_device_ = 0, last_accel_device_ = 0;
  bool have_gyro_device_ = false, have_accel_device_ = false;
  // The gyro half of the current IMU sample, waiting for its accelerometer frame.
  struct PendingGyro {
    bool valid = false;
    int counter = 0;
    std::uint32_t stamp_mod_us = 0;
    std::int64_t device_us = -1;
    std::array<double, 3> gyro{};
  } pending_;
  std::uint64_t imu_samples_ = 0;
  RateTimeline timeline_{firmware_iface::kMessageTypeCount + 2};
  BoundedSeries<6> imu_series_;
  BoundedSeries<2> cmd_series_, state_series_;
};

}  // namespace epichead::tools::replay
