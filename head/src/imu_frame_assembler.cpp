#include "epichead/head/imu_frame_assembler.h"

namespace epichead::head {
namespace {

bool same_sample(const firmware_iface::ImuVectorFrame& a, const firmware_iface::ImuVectorFrame& b) {
  return a.counter == b.counter && a.stamp_mod_us == b.stamp_mod_us;
}

}  // namespace

std::optional<fusion::ImuSample> ImuFrameAssembler::on_gyro(const firmware_iface::ImuGyro& g, double now_s,
                                                            const DeviceClockSync& sync) {
  if (!sync.synced()) { ++counters_.unsynced; return std::nullopt; }
  if (gyro_) ++counters_.unpaired;
  gyro_ = g;
  if (accel_ && !same_sample(*gyro_, *accel_)) { ++counters_.unpaired; accel_.reset(); }
  return join(now_s, sync);
}

std::optional<fusion::ImuSample> ImuFrameAssembler::on_accel(const firmware_iface::ImuAccel& a, double now_s,
                                                             const DeviceClockSync& sync) {
  if (!sync.synced()) { ++counters_.unsynced; return std::nullopt; }
  if (accel_) ++counters_.unpaired;
  accel_ = a;
  if (gyro_ && !same_sample(*gyro_, *accel_)) { ++counters_.unpaired; gyro_.reset(); }
  return join(now_s, sync);
}

std::optional<fusion::ImuSample> ImuFrameAssembler::join(double now_s, const DeviceClockSync& sync) {
  if (!gyro_ || !accel_) return std::nullopt;
  // The newest device time with this stamp that is not after the receive time, read on the
  // device's clock through the sync; the allowance covers the sync's error (half its round
  // trip) and 2 ms of margin, so a stamp just before the receive time is not put a wrap back.
  constexpr std::int64_t wrap = firmware_iface::kImuStampWrapUs;
  const auto allowance_us = 2000 + static_cast<std::int64_t>(sync.max_error_s() * 1e6);
  const std::int64_t received_us = sync.device_us_at(now_s) + allowance_us;
  const std::int64_t back = ((received_us - static_cast<std::int64_t>(gyro_->stamp_mod_us)) % wrap + wrap) % wrap;
  const std::int64_t device_us = received_us - back;
  fusion::ImuSample s;
  s.t_s = sync.to_controller_s(static_cast<std::uint64_t>(std::max<std::int64_t>(0, device_us)));
  s.gyro_radps = {gyro_->value[0], gyro_->value[1], gyro_->value[2]};
  s.accel_mps2 = {accel_->value[0], accel_->value[1], accel_->value[2]};
  if (gyro_->saturated || accel_->saturated) ++counters_.saturated;
  if (last_counter_) {
    const int step = (gyro_->counter - *last_counter_ + firmware_iface::kImuCounterModulo) % firmware_iface::kImuCounterModulo;
    if (step > 1) counters_.counter_gaps += static_cast<std::uint64_t>(step - 1);
  }
  last_counter_ = gyro_->counter;
  ++counters_.samples;
  gyro_.reset();
  accel_.reset();
  return s;
}

}  // namespace epichead::head
