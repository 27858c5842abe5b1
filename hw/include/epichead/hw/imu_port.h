#pragma once
// The IMU port: samples as the device reports them (its own clock stamp_us and rolling counter,
// SI units, camera axes) plus when the host received each one, for the time-sync estimate.
// Implemented by the hidapi reader (USB HID), the CAN IMU decoder and the simulator.
#include <cstdint>
#include <string_view>

#include "epichead/firmware_iface/imu_sample.h"

namespace epichead::hw {

struct ImuReading {
  firmware_iface::ImuSample sample;  // device stamp_us, counter, gyro_radps, accel_mps2
  double receive_t_s = 0;            // program monotonic time the host received it
};

enum class ImuRead {
  Sample,   // `out` holds the next sample
  Timeout,  // none within the timeout (still connected, or still reconnecting)
  Lost,     // the device went away now; the reader reconnects on later calls
};

struct ImuStats {
  std::uint64_t samples = 0;            // samples delivered
  std::uint64_t rejected_reports = 0;   // reports that did not decode (wrong id, short)
  std::uint64_t lost_samples = 0;       // gaps in the rolling counter
  std::uint64_t duplicate_samples = 0;  // same counter as the previous sample: dropped
  std::uint64_t disconnects = 0;
  std::uint64_t reconnects = 0;
  std::uint64_t reconnect_attempts = 0;
};

class ImuPort {
 public:
  virtual ~ImuPort() = default;
  // Waits up to timeout_s (0: do not wait; negative: forever) for the next sample.
  virtual ImuRead receive(ImuReading& out, double timeout_s) = 0;
  virtual ImuStats stats() const = 0;
  // The last rejected report or lost connection, in words (empty if none).
  virtual std::string_view last_error() const = 0;
};

}  // namespace epichead::hw
