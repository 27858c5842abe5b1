#pragma once
// A scripted HID device for the IMU reader: reports to hand out, plugged in or not; reads
// without a report wait out their timeout on the fake clock. SleepAdvancesClock makes the
// reader's sleeps between reconnect attempts advance the same clock.
#include <algorithm>
#include <deque>
#include <vector>

#include "epichead/hw/fake_clock.h"
#include "epichead/hw/hid_device.h"
#include "epichead/hw/syscalls.h"

namespace epichead::testing {

using hw::FakeClock;
using hw::HidDevice;
using hw::HidDeviceOptions;
using hw::HidOpener;

// What the scripted "device" holds: reports to hand out, whether it is plugged in.
struct FakeHid {
  std::deque<std::vector<std::uint8_t>> reports;
  bool present = true;
  bool fail_next_read = false;
  int opens = 0;
  FakeClock* clock = nullptr;
};

class FakeHidDevice final : public HidDevice {
 public:
  explicit FakeHidDevice(FakeHid& hid) : hid_(hid) {}
  int read(std::uint8_t* data, std::size_t size, int timeout_ms) override {
    if (!hid_.present || hid_.fail_next_read) {
      hid_.fail_next_read = false;
      return -1;
    }
    if (hid_.reports.empty()) {
      hid_.clock->advance(std::max(timeout_ms, 0) * 1e-3);
      return 0;
    }
    const auto& report = hid_.reports.front();
    const std::size_t n = std::min(size, report.size());
    std::copy_n(report.begin(), n, data);
    hid_.reports.pop_front();
    return static_cast<int>(n);
  }
  std::string error() const override { return "Input/output error"; }

 private:
  FakeHid& hid_;
};

// Sleeps between reconnect attempts advance the fake clock.
class SleepAdvancesClock : public hw::Syscalls {
 public:
  explicit SleepAdvancesClock(FakeClock& clock) : clock_(clock) {}
  int poll(pollfd*, nfds_t, int timeout_ms) override {
    clock_.advance(timeout_ms * 1e-3);
    return 0;
  }

 private:
  FakeClock& clock_;
};

inline HidOpener opener(FakeHid& hid) {
  return [&hid](const HidDeviceOptions& options) -> std::expected<std::unique_ptr<HidDevice>, std::string> {
    if (!hid.present) return std::unexpected("HID device " + options.path + ": not found");
    ++hid.opens;
    return std::make_unique<FakeHidDevice>(hid);
  };
}

}  // namespace epichead::testing
