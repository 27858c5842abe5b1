#pragma once
// One open HID device as the IMU reader needs it: read an input report with a timeout. The
// real one is hidapi over hidraw; tests pass their own, so the reader's logic (decode, counter
// gaps, reconnects) runs without a device.
#include <cstddef>
#include <cstdint>
#include <expected>
#include <functional>
#include <memory>
#include <string>

namespace epichead::hw {

struct HidDeviceOptions {
  std::uint16_t vendor_id = 0x1209;   // pid.codes; set to the IMU's own ids in the configuration
  std::uint16_t product_id = 0x0001;
  std::string serial;                 // empty: the first device with these ids
  std::string path;                   // a hidraw path (/dev/hidraw3); overrides the ids
};

class HidDevice {
 public:
  virtual ~HidDevice() = default;
  // Bytes of one input report (report ID first when the device numbers its reports), 0 on
  // timeout (timeout_ms < 0 waits forever), -1 when the device failed (error() says why).
  virtual int read(std::uint8_t* data, std::size_t size, int timeout_ms) = 0;
  virtual std::string error() const = 0;
};

using HidOpener = std::function<std::expected<std::unique_ptr<HidDevice>, std::string>(const HidDeviceOptions&)>;

// Opens a device with hidapi (hidraw backend); the error names the ids or path.
std::expected<std::unique_ptr<HidDevice>, std::string> open_hidapi_device(const HidDeviceOptions& options);

}  // namespace epichead::hw
