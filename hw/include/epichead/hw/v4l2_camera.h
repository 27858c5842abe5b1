#pragma once
// CameraPort over the Linux V4L2 capture API (single-planar, memory-mapped streaming): format
// negotiation from a preference list, buffer time stamps (CLOCK_MONOTONIC, the MonotonicClock's
// time base), sequence gaps and bad buffers counted, and recovery when the device disappears
// (ENODEV / POLLERR) and comes back (reopened every reconnect_interval_s).
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "epichead/hw/camera_port.h"
#include "epichead/hw/clock.h"
#include "epichead/hw/pixel_format.h"
#include "epichead/hw/syscalls.h"

namespace epichead::hw {

class Deadline;  // src/deadline.h

struct V4l2CameraOptions {
  std::string device = "/dev/video0";
  int width = 640, height = 480;        // requested; the driver may choose the nearest size
  std::vector<std::uint32_t> formats = {fourcc('G', 'R', 'E', 'Y'), fourcc('Y', 'U', 'Y', 'V')};  // by preference
  double frame_rate_hz = 0;             // > 0: asked of the driver (VIDIOC_S_PARM); 0: its current rate
  int buffers = 4;                      // mmap buffers requested (the driver may give more)
  double reconnect_interval_s = 0.5;    // between reopen attempts after the device went away
};

class V4l2Camera final : public CameraPort {
 public:
  // Opens the device and negotiates the format (not yet streaming). The error names the device
  // and the step that failed.
  static std::expected<std::unique_ptr<V4l2Camera>, std::string> open(
      const V4l2CameraOptions& options, Syscalls& sys = Syscalls::real(), Clock& clock = monotonic_clock());
  ~V4l2Camera() override;
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  std::expected<void, std::string> start() override;
  void stop() override;
  CameraRead next_frame(CameraFrame& out, double timeout_s) override;
  CameraState state() const override { return state_; }
  CameraStats stats() const override { return stats_; }
  std::string_view last_error() const override { return last_error_; }

  // The negotiated format (the frames' width, height, stride and pixel format).
  const CameraFrame& format() const { return format_; }

 private:
  struct Buffer {
    void* address = nullptr;
    std::size_t length = 0;
  };
  V4l2Camera(const V4l2CameraOptions& options, Syscalls& sys, Clock& clock);
  std::expected<void, std::string> open_device();
  std::expected<void, std::string> negotiate_format();
  std::expected<void, std::string> set_frame_rate();
  std::expected<void, std::string> start_streaming();
  void release_device();   // unmaps, closes; no ioctl (the device may be gone)
  CameraRead lose_device(int error);
  // Reopens when an attempt is due, sleeping between attempts until the deadline; true once streaming.
  bool try_reconnect(const Deadline& deadline);
  std::string error_text(const char* what, int error) const;

  V4l2CameraOptions options_;
  Syscalls& sys_;
  Clock& clock_;
  int fd_ = -1;
  CameraState state_ = CameraState::Stopped;
  CameraFrame format_;
  std::uint32_t sizeimage_ = 0;
  std::vector<Buffer> buffers_;
  int held_ = -1;                   // buffer index lent to the caller, requeued on the next call
  bool have_sequence_ = false;
  std::uint32_t last_sequence_ = 0;
  double next_attempt_s_ = 0;
  CameraStats stats_;
  std::string last_error_;
};

}  // namespace epichead::hw
