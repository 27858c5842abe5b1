#include "replay/log_analysis.h"

#include <cmath>
#include <limits>

#include "epichead/firmware_iface/protocol.h"
#include "epichead/firmware_iface/version.h"
#include "replay/frame_time.h"

namespace epichead::tools::replay {

namespace fw = firmware_iface;
using fw::MessageType;

namespace {
// Distinct ids kept in the per-id table; more (a fuzzed or corrupt log) are counted together.
constexpr std::size_t kMaxIds = 4096;

constexpr int counter_modulo(MessageType t) {
  switch (t) {
    case MessageType::ImuGyro:
    case MessageType::ImuAccel:
    case MessageType::HeadCommand:
    case MessageType::HeadState: return 16;
    case MessageType::HeadStatus: return 256;
    default: return 0;
  }
}
}  // namespace

LogAnalyzer::LogAnalyzer(AnalysisOptions options) : options_(std::move(options)) {
  for (int t = 0; t < fw::kMessageTypeCount; ++t) {
    const int m = counter_modulo(static_cast<MessageType>(t));
    messages_[static_cast<std::size_t>(t)].counter = CounterTracker(m > 0 ? m : 16);
  }
}

void LogAnalyzer::add(const fw::CandumpRecord& r) {
  const fw::CanFrame& f = r.frame.frame;
  ++frames_;
  const double bus_s = frame_time_s(f, options_.bitrate, options_.data_bitrate);
  bus_s_ += bus_s;
  const std::int64_t t_us = r.frame.stamp_us;
  if (r.has_stamp) {
    if (!have_stamp_) first_us_ = last_us_ = t_us;
    have_stamp_ = true;
    first_us_ = std::min(first_us_, t_us);
    last_us_ = std::max(last_us_, t_us);
  } else {
    ++unstamped_;
  }
  if (f.error()) ++error_frames_;

  const std::uint64_t key = f.id | (static_cast<std::uint64_t>(f.extended() ? 1 : 0) << 32) |
                            (static_cast<std::uint64_t>(f.error() ? 1 : 0) << 33);
  auto it = ids_.find(key);
  if (it == ids_.end() && ids_.size() < kMaxIds) {
    IdStats fresh;
    fresh.id = f.id;
    fresh.extended = f.extended();
    it = ids_.emplace(key, fresh).first;
  }
  if (it != ids_.end()) {
    IdStats& s = it->second;
    s.timing.add(t_us, r.has_stamp, bus_s);
    s.bytes += f.len;
    s.remote += f.remote() ? 1 : 0;
    s.fd += f.fd() ? 1 : 0;
  } else {
    ++ids_over_limit_;
  }

  const double t_s = t_us * 1e-6;
  const auto ours = f.extended() || f.error() ? std::nullopt : fw::classify_id(f.id);
  if (ours) {
    ++protocol_frames_;
    add_ours(r, ours->type, bus_s);
    if (r.has_stamp) timeline_.add(t_s, static_cast<int>(ours->type), bus_s);
    return;
  }
  if (fw::is_dronecan_raw_imu_frame(f)) {
    ++dronecan_.frames;
    if (r.has_stamp) timeline_.add(t_s, kTimelineDroneCan, bus_s);
    auto done = dronecan_decoder_.push(r.frame);
    if (!done) {
      ++dronecan_.errors;
      ++dronecan_.error_reasons[std::string(done.error().field)];
      return;
    }
    if (!done->has_value()) return;
    const fw::DroneCanRawImu& m = **done;
    ++dronecan_.transfers;
    ++dronecan_.per_node[m.source_node];
    dronecan_.timing.add(t_us, r.has_stamp, 0);
    if (!options_.imu_protocol || *options_.imu_protocol == fw::ImuProtocol::DroneCanRawImu) {
      ImuObservation o{t_s, static_cast<std::int64_t>(m.timestamp_us), m.gyro_radps, m.accel_mps2,
                       fw::ImuProtocol::DroneCanRawImu};
      ++imu_samples_;
      imu_series_.add(t_s, {o.gyro_radps[0], o.gyro_radps[1], o.gyro_radps[2], o.accel_mps2[0], o.accel_mps2[1],
                            o.accel_mps2[2]});
      if (options_.imu_observer) options_.imu_observer(o);
    }
    return;
  }
  ++unknown_frames_;
  if (r.has_stamp) timeline_.add(t_s, kTimelineOther, bus_s);
}

void LogAnalyzer::add_ours(const fw::CandumpRecord& r, MessageType type, double bus_s) {
  MessageStats& ms = messages_[static_cast<std::size_t>(type)];
  ms.timing.add(r.frame.stamp_us, r.has_stamp, bus_s);
  const auto decoded = fw::decode(r.frame.frame);
  if (!decoded) {
    ++ms.errors[static_cast<std::size_t>(decoded.error().kind)];
    return;
  }
  ++ms.decoded;
  const double t_s = r.frame.stamp_us * 1e-6;
  const double gap = ms.timing.last_gap_us();
  const double nominal = ms.timing.nominal_period_us();
  const bool use_imu = !options_.imu_protocol || *options_.imu_protocol == fw::ImuProtocol::Epichead;

  const auto imu_device_time = [&](fw::StampUnwrapper& clock, std::int64_t& last_log_us, std::uint32_t mod_us,
                                   std::uint64_t& last_device, bool& have_device) {
    const std::int64_t hint = r.has_stamp && last_log_us >= 0 ? r.frame.stamp_us - last_log_us : -1;
    const std::uint64_t device = clock.unwrap(mod_us, hint);
    if (have_device) ms.device_gaps_us.add(static_cast<double>(device - last_device));
    have_device = true;
    last_device = device;
    if (r.has_stamp) last_log_us = r.frame.stamp_us;
    return static_cast<std::int64_t>(device);
  };

  std::visit(
      [&](const auto& m) {
        using M = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<M, fw::ImuGyro>) {
          ms.counter.add(m.counter, gap, nominal);
          if (m.saturated) ++ms.saturated_frames;
          const std::int64_t dev = imu_device_time(gyro_clock_, last_gyro_log_us_, m.stamp_mod_us, last_gyro_device_,
                                                   have_gyro_device_);
          pending_ = {true, m.counter, m.stamp_mod_us, dev, m.value};
        } else if constexpr (std::is_same_v<M, fw::ImuAccel>) {
          ms.counter.add(m.counter, gap, nominal);
          if (m.saturated) ++ms.saturated_frames;
          imu_device_time(accel_clock_, last_accel_log_us_, m.stamp_mod_us, last_accel_device_, have_accel_device_);
          // A sample is complete when the accelerometer frame matches the pending gyro frame.
          if (pending_.valid && pending_.counter == m.counter && pending_.stamp_mod_us == m.stamp_mod_us && use_imu) {
            ImuObservation o{t_s, pending_.device_us, pending_.gyro, m.value, fw::ImuProtocol::Epichead};
            ++imu_samples_;
            imu_series_.add(t_s, {o.gyro_radps[0], o.gyro_radps[1], o.gyro_radps[2], o.accel_mps2[0],
                                  o.accel_mps2[1], o.accel_mps2[2]});
            if (options_.imu_observer) options_.imu_observer(o);
          }
          pending_.valid = false;
        } else if constexpr (std::is_same_v<M, fw::HeadCommand>) {
          ms.counter.add(m.counter, gap, nominal);
          if (m.saturated) ++ms.saturated_frames;
          cmd_series_.add(t_s, {m.pan_rad, m.tilt_rad});
        } else if constexpr (std::is_same_v<M, fw::HeadState>) {
          ms.counter.add(m.counter, gap, nominal);
          if (m.saturated) ++ms.saturated_frames;
          state_series_.add(t_s, {m.pan_rad, m.tilt_rad});
          if (options_.head_state_observer) options_.head_state_observer(t_s, m);
        } else if constexpr (std::is_same_v<M, fw::HeadStatus>) {
          ms.counter.add(m.counter, gap, nominal);
          if (m.saturated) ++ms.saturated_frames;
          for (int bit = 0; bit < 16; ++bit) {
            const bool set = (m.faults >> bit) & 1u, was = (last_faults_ >> bit) & 1u;
            FaultInfo& fi = faults_[static_cast<std::size_t>(bit)];
            if (set) ++fi.frames_with_bit;
            if (set && !was) {
              ++fi.raised;
              if (fi.first_t_s < 0) fi.first_t_s = t_s;
            }
          }
          last_faults_ = m.faults;
        } else if constexpr (std::is_same_v<M, fw::Heartbeat>) {
          HeartbeatInfo& hb = heartbeats_[m.node];
          ++hb.count;
          hb.last_state = static_cast<int>(m.state);
          hb.firmware = std::to_string(m.firmware_major) + "." + std::to_string(m.firmware_minor) + "." +
                        std::to_string(m.firmware_patch);
          hb.protocol_version = m.protocol_version;
          if (m.protocol_version != fw::kProtocolVersion) ++hb.protocol_mismatches;
          hb.last_uptime_s = m.uptime_s;
        }
      },
      *decoded);
}

void LogAnalyzer::finish() { dronecan_.timed_out = dronecan_decoder_.transfers_timed_out(); }

double LogAnalyzer::bus_load() const {
  if (!have_stamp_ || last_us_ <= first_us_) return std::numeric_limits<double>::quiet_NaN();
  return bus_s_ / ((last_us_ - first_us_) * 1e-6);
}

std::vector<const IdStats*> LogAnalyzer::ids() const {
  std::vector<const IdStats*> out;
  for (const auto& [key, s] : ids_) out.push_back(&s);
  return out;  // the key orders 11-bit ids first, then 29-bit, then error classes
}

std::uint64_t LogAnalyzer::unknown_ids() const {
  std::uint64_t n = 0;
  for (const auto& [key, s] : ids_) {
    const bool ours = !s.extended && (key >> 33) == 0 && fw::classify_id(s.id).has_value();
    const bool dronecan = s.extended && ((s.id >> 8) & 0xFFFF) == fw::kRawImuDataTypeId && !(s.id & 0x80);
    n += (ours || dronecan) ? 0 : 1;
  }
  return n;
}

}  // namespace epichead::tools::replay
