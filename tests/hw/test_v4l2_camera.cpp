#include <catch2/catch.hpp>

#include "epichead/hw/fake_clock.h"
#include "epichead/hw/v4l2_camera.h"
#include "fake_v4l2_kernel.h"

using namespace epichead::hw;
using epichead::testing::FakeV4l2Kernel;

namespace {

V4l2CameraOptions options_for(const FakeV4l2Kernel& kernel) {
  V4l2CameraOptions options;
  options.device = kernel.path;
  return options;
}

std::unique_ptr<V4l2Camera> open_streaming(FakeV4l2Kernel& kernel, FakeClock& clock) {
  auto camera = V4l2Camera::open(options_for(kernel), kernel, clock);
  REQUIRE(camera);
  REQUIRE((*camera)->start());
  return std::move(*camera);
}

}  // namespace

TEST_CASE("format negotiation takes the first preferred format the device has, with its stride", "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  kernel.formats = {V4L2_PIX_FMT_YUYV, V4L2_PIX_FMT_MJPEG};
  kernel.stride_padding = 64;
  auto camera = V4l2Camera::open(options_for(kernel), kernel, clock);  // prefers GREY, then YUYV
  REQUIRE(camera);
  const CameraFrame& f = (*camera)->format();
  CHECK(f.format == PixelFormat::Yuyv);
  CHECK(f.fourcc == V4L2_PIX_FMT_YUYV);
  CHECK(f.width == 320);
  CHECK(f.height == 240);
  CHECK(f.stride_bytes == 320 * 2 + 64);
  CHECK((*camera)->state() == CameraState::Stopped);
}

TEST_CASE("a device without any requested format is refused with what it offers", "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  kernel.formats = {V4L2_PIX_FMT_MJPEG, V4L2_PIX_FMT_RGB24};
  const auto camera = V4l2Camera::open(options_for(kernel), kernel, clock);
  REQUIRE_FALSE(camera);
  CHECK_THAT(camera.error(), Catch::Contains("/dev/video7") && Catch::Contains("GREY, YUYV") &&
                                 Catch::Contains("device offers: MJPG, RGB3"));
  CHECK(kernel.closes == 1);
}

TEST_CASE("an absent device or one that cannot capture fails with the device name", "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  kernel.present = false;
  auto camera = V4l2Camera::open(options_for(kernel), kernel, clock);
  REQUIRE_FALSE(camera);
  CHECK_THAT(camera.error(), Catch::Contains("'/dev/video7'") && Catch::Contains("cannot open"));
  kernel.present = true;
  kernel.capture_device = false;
  camera = V4l2Camera::open(options_for(kernel), kernel, clock);
  REQUIRE_FALSE(camera);
  CHECK_THAT(camera.error(), Catch::Contains("not a single-planar video capture device"));
}

TEST_CASE("streamed frames carry the buffer's time stamp, sequence and pixels, buffers go back to the driver",
          "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  auto camera = open_streaming(kernel, clock);
  CHECK(kernel.mapped == 4);
  CHECK(kernel.queued() == 4);
  kernel.frames_available = 3;
  CameraFrame frame;
  for (std::uint32_t k = 0; k < 3; ++k) {
    REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
    CHECK(frame.sequence == k);
    CHECK(frame.t_s == Approx(1000.0 + k / 30.0).margin(2e-6));
    CHECK(frame.size_bytes == 320u * 2 * 240);
    CHECK(frame.data[0] == k);
    CHECK(frame.data[frame.size_bytes - 1] == k);
    CHECK(kernel.queued() == 3);  // one buffer lent to the caller
  }
  CHECK(camera->next_frame(frame, 0.05) == CameraRead::Timeout);
  CHECK(kernel.queued() == 4);  // the lent buffer was requeued
  CHECK(camera->stats().frames == 3);
  camera->stop();
  CHECK(kernel.mapped == 0);
  CHECK(camera->next_frame(frame, 0) == CameraRead::Error);
}

TEST_CASE("bad buffers are requeued and counted, sequence gaps count as dropped frames", "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  auto camera = open_streaming(kernel, clock);
  kernel.frames_available = 3;
  kernel.bad_frames = {1};
  CameraFrame frame;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
  CHECK(frame.sequence == 0);
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
  CHECK(frame.sequence == 2);  // 1 came flagged bad
  CHECK(camera->stats().corrupt_frames == 1);
  CHECK(camera->stats().dropped_frames == 1);
  kernel.frames_available = 1;
  kernel.skip_before_next = 5;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
  CHECK(frame.sequence == 8);
  CHECK(camera->stats().dropped_frames == 6);
}

TEST_CASE("a buffer without a monotonic stamp is stamped on arrival and counted", "[hw][v4l2]") {
  FakeClock clock(50.0);
  FakeV4l2Kernel kernel(clock);
  kernel.monotonic_stamps = false;
  auto camera = open_streaming(kernel, clock);
  kernel.frames_available = 1;
  CameraFrame frame;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
  CHECK(frame.t_s == 50.0);
  CHECK(camera->stats().unstamped_frames == 1);
}

TEST_CASE("an unplugged camera is reported once, retried at the interval, and streams again when back",
          "[hw][v4l2]") {
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  auto camera = open_streaming(kernel, clock);
  kernel.frames_available = 1;
  CameraFrame frame;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);

  kernel.present = false;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Lost);
  CHECK(camera->state() == CameraState::Reconnecting);
  CHECK_THAT(std::string(camera->last_error()), Catch::Contains("device lost"));
  CHECK(kernel.mapped == 0);                     // buffers unmapped
  CHECK(kernel.closes == 1);                     // descriptor closed
  CHECK(camera->stats().disconnects == 1);

  // Absent for 2 s with the default 0.5 s interval: Timeout each call, about 4 attempts.
  for (int i = 0; i < 20; ++i) CHECK(camera->next_frame(frame, 0.1) == CameraRead::Timeout);
  CHECK(camera->stats().reconnect_attempts >= 3);
  CHECK(camera->stats().reconnect_attempts <= 5);
  CHECK(camera->state() == CameraState::Reconnecting);

  kernel.present = true;
  kernel.frames_available = 1;
  REQUIRE(camera->next_frame(frame, 1.0) == CameraRead::Frame);
  CHECK(camera->state() == CameraState::Streaming);
  CHECK(camera->stats().reconnects == 1);
  CHECK(camera->stats().disconnects == 1);
  CHECK(kernel.streamons == 2);
  CHECK(kernel.mapped == 4);
}

TEST_CASE("a camera that vanishes between poll and DQBUF is lost, not crashed", "[hw][v4l2]") {
  // Present at poll time is not modelled separately: an ioctl failing with ENODEV on the
  // requeue of the lent buffer is the same path.
  FakeClock clock;
  FakeV4l2Kernel kernel(clock);
  auto camera = open_streaming(kernel, clock);
  kernel.frames_available = 1;
  CameraFrame frame;
  REQUIRE(camera->next_frame(frame, 0.1) == CameraRead::Frame);
  kernel.present = false;
  kernel.frames_available = 1;
  CHECK(camera->next_frame(frame, 0) == CameraRead::Lost);
  CHECK(camera->next_frame(frame, 0) == CameraRead::Timeout);
}

TEST_CASE("on this kernel, a missing device node and a non-V4L2 file give clear errors", "[hw][v4l2]") {
  V4l2CameraOptions options;
  options.device = "/dev/video_epichead_absent";
  auto camera = V4l2Camera::open(options);
  REQUIRE_FALSE(camera);
  CHECK_THAT(camera.error(), Catch::Contains("'/dev/video_epichead_absent'") &&
                                 Catch::Contains("No such file or directory"));
  options.device = "/dev/null";
  camera = V4l2Camera::open(options);
  REQUIRE_FALSE(camera);
  CHECK_THAT(camera.error(), Catch::Contains("not a V4L2 device"));
}
