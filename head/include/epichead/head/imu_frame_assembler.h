#pragma once
// Joins the IMU's gyro and accelerometer CAN frames (sent as a pair per sample, same counter and
// wrapped stamp) into one sample on the controller's clock. The 65.536 ms stamp is unwrapped
// against the device clock that time synchronisation predicts for the receive time (a sample is
// always received after it was taken), so a long bus gap cannot slip it by a wrap.
#include <cstdint>
#include <optional>

#include "epichead/firmware_iface/imu_frames.h"
#include "epichead/fusion/imu_sample.h"
#include "epichead/head/device_clock_sync.h"

namespace epichead::head {

struct ImuAssemblyCounters {
  std::uint64_t samples = 0;          // pairs joined
  std::uint64_t unpaired = 0;         // a half whose partner never came (replaced by a newer half)
  std::uint64_t unsynced = 0;         // halves received before the clock was synchronised
  std::uint64_t counter_gaps = 0;     // samples missing according to the rolling counter
  std::uint64_t saturated = 0;        // samples with any axis at the wire's limit
};

class ImuFrameAssembler {
 public:
  // A decoded half received at controller time now_s; returns the joined sample when this half
  // completes a pair. `sync` maps the device clock (must be the IMU node's).
  std::optional<fusion::ImuSample> on_gyro(const firmware_iface::ImuGyro& g, double now_s, const DeviceClockSync& sync);
  std::optional<fusion::ImuSample> on_accel(const firmware_iface::ImuAccel& a, double now_s, const DeviceClockSync& sync);
  const ImuAssemblyCounters& counters() const { return counters_; }

 private:
  std::optional<fusion::ImuSample> join(double now_s, const DeviceClockSync& sync);
  std::optional<firmware_iface::ImuGyro> gyro_;
  std::optional<firmware_iface::ImuAccel> accel_;
  std::optional<std::uint8_t> last_counter_;
  ImuAssemblyCounters counters_;
};

}  // namespace epichead::head
