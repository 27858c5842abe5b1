// The drivers' per-frame and per-sample paths make no heap allocation after start-up (STYLE.md:
// hot paths). Counted here, against the fake kernels, with the replaced global operator new of
// common/allocation_counter.h; timing is left to benchmarks.
#include <catch2/catch.hpp>

#include <linux/can/error.h>

#include "epichead/common/allocation_counter.h"
#include "epichead/firmware_iface/hid_imu_report.h"
#include "epichead/hw/fake_clock.h"
#include "epichead/hw/hid_imu_reader.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/hw/v4l2_camera.h"
#include "fake_can_kernel.h"
#include "fake_hid_device.h"
#include "fake_v4l2_kernel.h"

using namespace epichead::hw;
using namespace epichead::testing;

TEST_CASE("receiving CAN frames, error frames and drop counts allocates nothing", "[hw][socketcan][alloc]") {
  FakeCanKernel kernel;
  FakeClock clock;
  auto bus = SocketCanBus::open({}, kernel, clock);
  REQUIRE(bus);
  for (std::uint32_t i = 0; i < 1000; ++i) {
    kernel.push(i % 2 ? 0x123 : (CAN_ERR_FLAG | CAN_ERR_CRTL), {1, 2, 3, 4, 5, 6, 7, 8}, timeval{1, 0}, i / 10);
  }
  kernel.written.reserve(100);
  CanFrame out_frame;
  out_frame.len = 8;
  StampedCanFrame got;
  const auto before = epichead::common::allocation_count();
  int frames = 0;
  while ((*bus)->receive(got, 0) == CanReceive::Frame) ++frames;
  int sent = 0;
  for (int i = 0; i < 100; ++i) sent += (*bus)->send(out_frame).has_value() ? 1 : 0;
  const auto after = epichead::common::allocation_count();  // before any assertion: Catch itself allocates
  CHECK(frames == 1000);
  CHECK(sent == 100);
  CHECK(after - before == 0);
}

TEST_CASE("streaming V4L2 frames allocates nothing", "[hw][v4l2][alloc]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  V4l2CameraOptions options;
  options.device = kernel.path;
  auto camera = V4l2Camera::open(options, kernel, clock);
  REQUIRE(camera);
  REQUIRE((*camera)->start());
  kernel.frames_available = 300;
  CameraFrame frame;
  const auto before = epichead::common::allocation_count();
  int frames = 0;
  while ((*camera)->next_frame(frame, 0) == CameraRead::Frame) ++frames;
  const auto after = epichead::common::allocation_count();
  CHECK(frames == 300);
  CHECK(after - before == 0);
}

TEST_CASE("reading HID IMU samples allocates nothing", "[hw][hid][alloc]") {
  FakeClock clock;
  FakeHid hid;
  hid.clock = &clock;
  SleepAdvancesClock sys(clock);
  auto reader = HidImuReader::open({}, opener(hid), clock, sys);
  REQUIRE(reader);
  for (int k = 0; k < 500; ++k) {
    epichead::firmware_iface::ImuSample s;
    s.counter = static_cast<std::uint8_t>(k);
    const auto report = epichead::firmware_iface::encode_hid_imu_report(s);
    REQUIRE(report);
    hid.reports.emplace_back(report->bytes.begin(), report->bytes.end());
  }
  ImuReading reading;
  const auto before = epichead::common::allocation_count();
  int samples = 0;
  while ((*reader)->receive(reading, 0) == ImuRead::Sample) ++samples;
  const auto after = epichead::common::allocation_count();
  CHECK(samples == 500);
  CHECK(after - before == 0);
}
