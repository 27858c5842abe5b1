#include <hidapi.h>

#include <cstdio>
#include <cwchar>

#include "epichead/hw/hid_device.h"

namespace epichead::hw {
namespace {

// hidapi reports errors as wide strings; the messages are ASCII in practice, and a locale
// dependent conversion (wcstombs) would fail under the C locale, so non-ASCII becomes '?'.
std::string narrow(const wchar_t* text) {
  std::string out;
  if (text == nullptr) return out;
  for (; *text != 0; ++text) out += (*text > 0 && *text < 0x80) ? static_cast<char>(*text) : '?';
  return out;
}

std::wstring widen(const std::string& text) { return std::wstring(text.begin(), text.end()); }

bool hidapi_ready() {
  static const bool ready = hid_init() == 0;  // once per process; hid_exit is left to exit
  return ready;
}

class HidapiDevice final : public HidDevice {
 public:
  explicit HidapiDevice(hid_device* device) : device_(device) {}
  ~HidapiDevice() override { hid_close(device_); }
  HidapiDevice(const HidapiDevice&) = delete;
  HidapiDevice& operator=(const HidapiDevice&) = delete;
  int read(std::uint8_t* data, std::size_t size, int timeout_ms) override {
    return hid_read_timeout(device_, data, size, timeout_ms);
  }
  std::string error() const override { return narrow(hid_error(device_)); }

 private:
  hid_device* device_;
};

}  // namespace

std::expected<std::unique_ptr<HidDevice>, std::string> open_hidapi_device(const HidDeviceOptions& options) {
  char ids[32];
  std::snprintf(ids, sizeof ids, "%04x:%04x", options.vendor_id, options.product_id);
  const std::string what = options.path.empty()
                               ? "HID device " + std::string(ids) + (options.serial.empty() ? "" : " serial " + options.serial)
                               : "HID device '" + options.path + "'";
  if (!hidapi_ready()) return std::unexpected(what + ": hidapi cannot start (hid_init failed)");
  hid_device* device = nullptr;
  if (!options.path.empty()) {
    device = hid_open_path(options.path.c_str());
  } else {
    const std::wstring serial = widen(options.serial);
    device = hid_open(options.vendor_id, options.product_id, options.serial.empty() ? nullptr : serial.c_str());
  }
  if (device == nullptr) {
    std::string reason = narrow(hid_error(nullptr));
    if (reason.empty()) reason = "not found";
    return std::unexpected(what + ": cannot open: " + reason + " (is it plugged in, and is /dev/hidraw* readable?)");
  }
  hid_set_nonblocking(device, 0);  // reads wait up to their timeout
  return std::make_unique<HidapiDevice>(device);
}

}  // namespace epichead::hw
