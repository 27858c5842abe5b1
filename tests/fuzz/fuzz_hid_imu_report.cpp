// The USB HID IMU report (hid_imu_report.h). Properties: no crash; a report shorter than
// kHidImuReportSize or with another report ID is rejected; a decoded sample encodes, without
// clipping, back into the report's first kHidImuReportSize bytes.
#include <cstring>
#include <span>

#include "epichead/firmware_iface/hid_imu_report.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto sample = decode_hid_imu_report(std::span<const std::uint8_t>(data, size));
  if (size < kHidImuReportSize || (size > 0 && data[0] != kHidImuReportId)) {
    check(!sample.has_value(), "a short report or a wrong report ID was accepted");
  }
  if (!sample) {
    epichead::fuzz::check_one_line(sample.error().message(), "wire error");
    return 0;
  }
  const auto report = encode_hid_imu_report(*sample);
  check(report.has_value(), "a decoded sample does not encode");
  check(report->clipped == 0, "a decoded sample is clipped when encoded");
  check(std::memcmp(report->bytes.data(), data, kHidImuReportSize) == 0, "decode -> encode changed the report");
  const auto again = decode_hid_imu_report(report->bytes);
  check(again.has_value() && again->counter == sample->counter && again->stamp_us == sample->stamp_us &&
            again->gyro_radps == sample->gyro_radps && again->accel_mps2 == sample->accel_mps2 &&
            again->saturated == sample->saturated,
        "the re-encoded report decodes to another sample");
  return 0;
}
