#pragma once
// ImuPort over a USB HID IMU: reads input reports, decodes them with the protocol's
// firmware_iface::decode_hid_imu_report, stamps the host receive time, counts rejected reports
// and counter gaps, and reopens the device (every reconnect_interval_s) after it went away.
#include <array>
#include <cstdint>
#include <expected>
#include <memory>
#include <optional>
#include <string>

#include "epichead/hw/clock.h"
#include "epichead/hw/hid_device.h"
#include "epichead/hw/imu_port.h"
#include "epichead/hw/syscalls.h"

namespace epichead::hw {

class Deadline;  // src/deadline.h

struct HidImuOptions {
  HidDeviceOptions device;
  double reconnect_interval_s = 0.5;
};

class HidImuReader final : public ImuPort {
 public:
  // Opens the device now, so a missing IMU is a clear error at start-up. `open_device` defaults
  // to hidapi; `sys` is used only to sleep between reconnect attempts.
  static std::expected<std::unique_ptr<HidImuReader>, std::string> open(
      const HidImuOptions& options, HidOpener open_device = open_hidapi_device, Clock& clock = monotonic_clock(),
      Syscalls& sys = Syscalls::real());

  ImuRead receive(ImuReading& out, double timeout_s) override;
  ImuStats stats() const override { return stats_; }
  std::string_view last_error() const override { return last_error_; }
  bool connected() const { return device_ != nullptr; }

 private:
  HidImuReader(const HidImuOptions& options, HidOpener open_device, Clock& clock, Syscalls& sys);
  bool try_reconnect(const Deadline& deadline);

  HidImuOptions options_;
  HidOpener open_device_;
  Clock& clock_;
  Syscalls& sys_;
  std::unique_ptr<HidDevice> device_;
  std::array<std::uint8_t, 64> report_{};  // one full-speed interrupt packet
  std::optional<std::uint8_t> last_counter_;
  double next_attempt_s_ = 0;
  ImuStats stats_;
  std::string last_error_;
};

}  // namespace epichead::hw
