#include <catch2/catch.hpp>

#include <deque>
#include <vector>

#include "epichead/firmware_iface/hid_imu_report.h"
#include "epichead/hw/fake_clock.h"
#include "epichead/hw/hid_imu_reader.h"
#include "fake_hid_device.h"

using namespace epichead::hw;
using namespace epichead::testing;
namespace fw = epichead::firmware_iface;

namespace {

std::vector<std::uint8_t> report(std::uint8_t counter, std::uint32_t stamp_us, double gyro_x_radps) {
  fw::ImuSample s;
  s.counter = counter;
  s.stamp_us = stamp_us;
  s.gyro_radps = {gyro_x_radps, 0, 0};
  s.accel_mps2 = {0, 0, 9.8};
  const auto encoded = fw::encode_hid_imu_report(s);
  REQUIRE(encoded);
  return {encoded->bytes.begin(), encoded->bytes.end()};
}

struct Rig {
  FakeClock clock{10.0};
  FakeHid hid;
  SleepAdvancesClock sys{clock};
  std::unique_ptr<HidImuReader> reader;
  Rig() {
    hid.clock = &clock;
    auto r = HidImuReader::open({}, opener(hid), clock, sys);
    REQUIRE(r);
    reader = std::move(*r);
  }
};

}  // namespace

TEST_CASE("HID reports decode into samples with the device stamp and the host receive time", "[hw][hid]") {
  Rig rig;
  rig.hid.reports.push_back(report(7, 123456, 0.5));
  ImuReading reading;
  REQUIRE(rig.reader->receive(reading, 0.1) == ImuRead::Sample);
  CHECK(reading.sample.counter == 7);
  CHECK(reading.sample.stamp_us == 123456u);
  CHECK(reading.sample.gyro_radps[0] == Approx(0.5).margin(fw::kGyroRadpsPerLsb));
  CHECK(reading.sample.accel_mps2[2] == Approx(9.8).margin(fw::kAccelMps2PerLsb));
  CHECK(reading.receive_t_s == 10.0);
  CHECK(rig.reader->receive(reading, 0.1) == ImuRead::Timeout);
  CHECK(rig.reader->stats().samples == 1);
}

TEST_CASE("counter gaps count lost samples across the 8-bit wrap, repeats are dropped", "[hw][hid]") {
  Rig rig;
  for (int c : {254, 255, 2, 2, 3}) rig.hid.reports.push_back(report(static_cast<std::uint8_t>(c), 0, 0));
  ImuReading reading;
  std::vector<int> counters;
  while (rig.reader->receive(reading, 0) == ImuRead::Sample) counters.push_back(reading.sample.counter);
  CHECK(counters == std::vector<int>{254, 255, 2, 3});
  CHECK(rig.reader->stats().lost_samples == 2);  // 0 and 1
  CHECK(rig.reader->stats().duplicate_samples == 1);
}

TEST_CASE("reports that do not decode are counted with the reason and skipped", "[hw][hid]") {
  Rig rig;
  auto wrong_id = report(1, 0, 0);
  wrong_id[0] = 0x02;
  rig.hid.reports.push_back(wrong_id);
  rig.hid.reports.push_back({0x01, 0x00, 0x01});  // short
  rig.hid.reports.push_back(report(2, 0, 0));
  ImuReading reading;
  REQUIRE(rig.reader->receive(reading, 0.1) == ImuRead::Sample);
  CHECK(reading.sample.counter == 2);
  CHECK(rig.reader->stats().rejected_reports == 2);
  CHECK_THAT(std::string(rig.reader->last_error()), Catch::Contains("HID IMU report"));
}

TEST_CASE("an unplugged IMU is reported once and reopened at the interval when it is back", "[hw][hid]") {
  Rig rig;
  rig.hid.present = false;
  ImuReading reading;
  REQUIRE(rig.reader->receive(reading, 0.1) == ImuRead::Lost);
  CHECK_FALSE(rig.reader->connected());
  for (int i = 0; i < 20; ++i) CHECK(rig.reader->receive(reading, 0.1) == ImuRead::Timeout);  // 2 s away
  CHECK(rig.reader->stats().reconnect_attempts >= 3);
  CHECK(rig.reader->stats().reconnect_attempts <= 5);
  CHECK_THAT(std::string(rig.reader->last_error()), Catch::Contains("not found"));
  rig.hid.present = true;
  rig.hid.reports.push_back(report(9, 0, 0));
  REQUIRE(rig.reader->receive(reading, 1.0) == ImuRead::Sample);
  CHECK(rig.reader->stats().disconnects == 1);
  CHECK(rig.reader->stats().reconnects == 1);
  CHECK(rig.hid.opens == 2);
  CHECK(rig.reader->stats().lost_samples == 0);  // no gap counted across a reconnection
}

TEST_CASE("on this machine, a HID IMU that is not plugged in gives a clear error", "[hw][hid]") {
  HidImuOptions options;
  options.device.vendor_id = 0x1209;
  options.device.product_id = 0xEEEE;
  auto reader = HidImuReader::open(options);
  REQUIRE_FALSE(reader);
  CHECK_THAT(reader.error(), Catch::Contains("1209:eeee") && Catch::Contains("cannot open"));
  options.device.path = "/dev/hidraw_epichead_absent";
  reader = HidImuReader::open(options);
  REQUIRE_FALSE(reader);
  CHECK_THAT(reader.error(), Catch::Contains("'/dev/hidraw_epichead_absent'"));
}
