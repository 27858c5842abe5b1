#include <algorithm>
#include <cmath>
#include <span>

#include "epichead/firmware_iface/hid_imu_report.h"
#include "epichead/hw/hid_imu_reader.h"
#include "deadline.h"

namespace epichead::hw {

HidImuReader::HidImuReader(const HidImuOptions& options, HidOpener open_device, Clock& clock, Syscalls& sys)
    : options_(options), open_device_(std::move(open_device)), clock_(clock), sys_(sys) {}

std::expected<std::unique_ptr<HidImuReader>, std::string> HidImuReader::open(const HidImuOptions& options,
                                                                             HidOpener open_device, Clock& clock,
                                                                             Syscalls& sys) {
  std::unique_ptr<HidImuReader> reader(new HidImuReader(options, std::move(open_device), clock, sys));
  auto device = reader->open_device_(options.device);
  if (!device) return std::unexpected(device.error());
  reader->device_ = std::move(*device);
  return reader;
}

bool HidImuReader::try_reconnect(const Deadline& deadline) {
  for (;;) {
    if (clock_.now_s() >= next_attempt_s_) {
      ++stats_.reconnect_attempts;
      auto device = open_device_(options_.device);
      if (device) {
        device_ = std::move(*device);
        ++stats_.reconnects;
        last_counter_.reset();  // a new connection: no gap to count against the old one
        return true;
      }
      last_error_ = device.error();
      next_attempt_s_ = clock_.now_s() + options_.reconnect_interval_s;
    }
    const double now_s = clock_.now_s();
    if (!deadline.forever() && now_s >= deadline.end_s()) return false;
    const double wake_s = deadline.forever() ? next_attempt_s_ : std::min(next_attempt_s_, deadline.end_s());
    sys_.poll(nullptr, 0, static_cast<int>(std::ceil(std::max(0.0, wake_s - now_s) * 1e3)));  // sleep
  }
}

ImuRead HidImuReader::receive(ImuReading& out, double timeout_s) {
  const Deadline deadline(clock_, timeout_s);
  for (;;) {
    if (!device_ && !try_reconnect(deadline)) return ImuRead::Timeout;
    const int n = device_->read(report_.data(), report_.size(), deadline.remaining_ms());
    if (n < 0) {
      last_error_ = "HID IMU: device lost: " + device_->error();
      device_.reset();
      ++stats_.disconnects;
      next_attempt_s_ = clock_.now_s() + options_.reconnect_interval_s;
      return ImuRead::Lost;
    }
    if (n == 0) return ImuRead::Timeout;
    const double receive_t_s = clock_.now_s();
    const auto sample = firmware_iface::decode_hid_imu_report(std::span(report_.data(), static_cast<std::size_t>(n)));
    if (!sample) {
      ++stats_.rejected_reports;
      last_error_ = "HID IMU report: " + sample.error().message();
    } else {
      // The counter is 8 bits, +1 per sample: the modular step says how many went missing.
      const std::uint8_t step = last_counter_ ? static_cast<std::uint8_t>(sample->counter - *last_counter_) : 1;
      if (step == 0) {
        ++stats_.duplicate_samples;
      } else {
        stats_.lost_samples += step - 1u;
        last_counter_ = sample->counter;
        out.sample = *sample;
        out.receive_t_s = receive_t_s;
        ++stats_.samples;
        return ImuRead::Sample;
      }
    }
    // Skipped: read on (with no time left the read does not wait and ends in Timeout).
  }
}

}  // namespace epichead::hw
