#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

#include "epichead/hw/v4l2_camera.h"
#include "deadline.h"

namespace epichead::hw {
namespace {

// An error errno that means the device itself is gone or broken (unplugged, driver unbound),
// as opposed to "try again".
bool device_gone(int error) { return error == ENODEV || error == EIO || error == ENXIO || error == EBADF; }

}  // namespace

V4l2Camera::V4l2Camera(const V4l2CameraOptions& options, Syscalls& sys, Clock& clock)
    : options_(options), sys_(sys), clock_(clock) {}

V4l2Camera::~V4l2Camera() {
  if (state_ == CameraState::Streaming) stop();
  release_device();
}

std::string V4l2Camera::error_text(const char* what, int error) const {
  std::string text = "V4L2 camera '" + options_.device + "': " + what;
  if (error != 0) text += std::string(": ") + std::strerror(error);
  return text;
}

std::expected<std::unique_ptr<V4l2Camera>, std::string> V4l2Camera::open(const V4l2CameraOptions& options,
                                                                         Syscalls& sys, Clock& clock) {
  std::unique_ptr<V4l2Camera> camera(new V4l2Camera(options, sys, clock));
  if (options.buffers < 2 || options.buffers > 32) {
    return std::unexpected(camera->error_text("buffers must be 2 to 32", 0));
  }
  if (options.formats.empty()) return std::unexpected(camera->error_text("no pixel format requested", 0));
  if (!(options.frame_rate_hz >= 0 && options.frame_rate_hz <= 10000)) {
    return std::unexpected(camera->error_text("frame_rate_hz must be 0 (the driver's) to 10000", 0));
  }
  if (auto opened = camera->open_device(); !opened) return std::unexpected(opened.error());
  return camera;
}

std::expected<void, std::string> V4l2Camera::open_device() {
  // Non-blocking: DQBUF returns EAGAIN instead of sleeping, and waiting is poll's job.
  fd_ = sys_.open(options_.device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) return std::unexpected(error_text("cannot open", errno));
  v4l2_capability cap{};
  if (sys_.ioctl(fd_, VIDIOC_QUERYCAP, &cap) < 0) {
    const int error = errno;
    release_device();
    return std::unexpected(error_text("not a V4L2 device (VIDIOC_QUERYCAP)", error));
  }
  const std::uint32_t caps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  const char* missing = !(caps & V4L2_CAP_VIDEO_CAPTURE) ? "not a single-planar video capture device"
                        : !(caps & V4L2_CAP_STREAMING)   ? "no streaming I/O (mmap) support"
                                                         : nullptr;
  if (missing != nullptr) {
    release_device();
    return std::unexpected(error_text(missing, 0));
  }
  if (auto negotiated = negotiate_format(); !negotiated) {
    release_device();
    return negotiated;
  }
  if (auto rate = set_frame_rate(); !rate) {
    release_device();
    return rate;
  }
  return {};
}

std::expected<void, std::string> V4l2Camera::set_frame_rate() {
  if (options_.frame_rate_hz <= 0) return {};
  v4l2_streamparm p{};
  p.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (sys_.ioctl(fd_, VIDIOC_G_PARM, &p) < 0 || !(p.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    return std::unexpected(error_text("the driver cannot set a frame rate (no V4L2_CAP_TIMEPERFRAME)", 0));
  }
  // A frame interval of 1000 / (rate * 1000) s keeps fractional rates (7.5 Hz) exact.
  p.parm.capture.timeperframe.numerator = 1000;
  p.parm.capture.timeperframe.denominator = static_cast<std::uint32_t>(std::lround(options_.frame_rate_hz * 1000));
  if (sys_.ioctl(fd_, VIDIOC_S_PARM, &p) < 0) return std::unexpected(error_text("cannot set the frame rate (VIDIOC_S_PARM)", errno));
  // The driver answers with the nearest interval it supports, and streams at that one.
  return {};
}

std::expected<void, std::string> V4l2Camera::negotiate_format() {
  for (const std::uint32_t code : options_.formats) {
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix.width = static_cast<std::uint32_t>(std::max(options_.width, 1));
    f.fmt.pix.height = static_cast<std::uint32_t>(std::max(options_.height, 1));
    f.fmt.pix.pixelformat = code;
    f.fmt.pix.field = V4L2_FIELD_NONE;
    if (sys_.ioctl(fd_, VIDIOC_S_FMT, &f) < 0) {
      if (errno == EINVAL) continue;  // old drivers refuse instead of proposing another format
      return std::unexpected(error_text("cannot set the format (VIDIOC_S_FMT)", errno));
    }
    // The driver answers with the nearest format it supports; take it only if it is this one.
    if (f.fmt.pix.pixelformat != code) continue;
    const PixelFormat format = pixel_format_from_fourcc(code);
    const std::uint32_t min_stride = f.fmt.pix.width * static_cast<std::uint32_t>(bytes_per_pixel(format));
    const std::uint32_t stride = f.fmt.pix.bytesperline != 0 ? f.fmt.pix.bytesperline : min_stride;
    if (f.fmt.pix.width == 0 || f.fmt.pix.height == 0 || stride < min_stride || f.fmt.pix.width > 65535 ||
        f.fmt.pix.height > 65535 || (min_stride != 0 && f.fmt.pix.sizeimage < stride * f.fmt.pix.height)) {
      return std::unexpected(error_text(("driver answered an inconsistent format " + fourcc_to_string(code) + " " +
                                         std::to_string(f.fmt.pix.width) + "x" + std::to_string(f.fmt.pix.height) +
                                         " stride " + std::to_string(stride) + " size " +
                                         std::to_string(f.fmt.pix.sizeimage)).c_str(), 0));
    }
    format_ = CameraFrame{};
    format_.width = static_cast<int>(f.fmt.pix.width);
    format_.height = static_cast<int>(f.fmt.pix.height);
    format_.stride_bytes = static_cast<int>(stride);
    format_.format = format;
    format_.fourcc = code;
    sizeimage_ = f.fmt.pix.sizeimage;
    return {};
  }
  // None taken: list what the device offers so the configuration can be fixed.
  std::string offered;
  for (std::uint32_t i = 0; i < 64; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (sys_.ioctl(fd_, VIDIOC_ENUM_FMT, &d) < 0) break;
    offered += (offered.empty() ? "" : ", ") + fourcc_to_string(d.pixelformat);
  }
  std::string wanted;
  for (const std::uint32_t code : options_.formats) wanted += (wanted.empty() ? "" : ", ") + fourcc_to_string(code);
  return std::unexpected(error_text(("none of the formats " + wanted + " is supported (device offers: " +
                                     (offered.empty() ? "nothing listed" : offered) + ")").c_str(), 0));
}

std::expected<void, std::string> V4l2Camera::start_streaming() {
  v4l2_requestbuffers request{};
  request.count = static_cast<std::uint32_t>(options_.buffers);
  request.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  request.memory = V4L2_MEMORY_MMAP;
  if (sys_.ioctl(fd_, VIDIOC_REQBUFS, &request) < 0) {
    return std::unexpected(error_text("cannot allocate buffers (VIDIOC_REQBUFS)", errno));
  }
  if (request.count < 2 || request.count > 64) {
    return std::unexpected(error_text(("driver gave " + std::to_string(request.count) + " buffers, need 2 to 64").c_str(), 0));
  }
  buffers_.clear();
  buffers_.reserve(request.count);
  for (std::uint32_t i = 0; i < request.count; ++i) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    b.index = i;
    if (sys_.ioctl(fd_, VIDIOC_QUERYBUF, &b) < 0) {
      return std::unexpected(error_text("cannot query a buffer (VIDIOC_QUERYBUF)", errno));
    }
    void* address = sys_.mmap(b.length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, b.m.offset);
    if (address == MAP_FAILED) return std::unexpected(error_text("cannot map a buffer (mmap)", errno));
    buffers_.push_back({address, b.length});
    if (sys_.ioctl(fd_, VIDIOC_QBUF, &b) < 0) return std::unexpected(error_text("cannot queue a buffer (VIDIOC_QBUF)", errno));
  }
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (sys_.ioctl(fd_, VIDIOC_STREAMON, &type) < 0) return std::unexpected(error_text("cannot start streaming (VIDIOC_STREAMON)", errno));
  held_ = -1;
  have_sequence_ = false;
  return {};
}

std::expected<void, std::string> V4l2Camera::start() {
  if (state_ != CameraState::Stopped) return {};  // streaming, or reconnecting to stream
  if (fd_ < 0) {
    if (auto opened = open_device(); !opened) return opened;
  }
  if (auto started = start_streaming(); !started) {
    release_device();  // a half-set-up device is closed; start() reopens it
    last_error_ = started.error();
    return started;
  }
  state_ = CameraState::Streaming;
  return {};
}

void V4l2Camera::stop() {
  if (state_ == CameraState::Streaming && fd_ >= 0) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    sys_.ioctl(fd_, VIDIOC_STREAMOFF, &type);  // failure is harmless: the buffers are freed next
    for (const Buffer& b : buffers_) sys_.munmap(b.address, b.length);
    buffers_.clear();
    v4l2_requestbuffers none{};
    none.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    none.memory = V4L2_MEMORY_MMAP;
    sys_.ioctl(fd_, VIDIOC_REQBUFS, &none);
  }
  held_ = -1;
  state_ = CameraState::Stopped;
}

void V4l2Camera::release_device() {
  for (const Buffer& b : buffers_) sys_.munmap(b.address, b.length);
  buffers_.clear();
  held_ = -1;
  if (fd_ >= 0) sys_.close(fd_);
  fd_ = -1;
}

CameraRead V4l2Camera::lose_device(int error) {
  last_error_ = error_text("device lost", error);
  release_device();
  state_ = CameraState::Reconnecting;
  ++stats_.disconnects;
  next_attempt_s_ = clock_.now_s() + options_.reconnect_interval_s;
  return CameraRead::Lost;
}

bool V4l2Camera::try_reconnect(const Deadline& deadline) {
  for (;;) {
    if (clock_.now_s() >= next_attempt_s_) {
      ++stats_.reconnect_attempts;
      auto opened = open_device();
      if (opened) opened = start_streaming();
      if (opened) {
        state_ = CameraState::Streaming;
        ++stats_.reconnects;
        return true;
      }
      release_device();
      last_error_ = opened.error();
      next_attempt_s_ = clock_.now_s() + options_.reconnect_interval_s;
    }
    const double now_s = clock_.now_s();
    if (!deadline.forever() && now_s >= deadline.end_s()) return false;
    // Sleep until the next attempt or the deadline, whichever comes first (poll with no fds).
    const double wake_s = deadline.forever() ? next_attempt_s_ : std::min(next_attempt_s_, deadline.end_s());
    sys_.poll(nullptr, 0, static_cast<int>(std::ceil(std::max(0.0, wake_s - now_s) * 1e3)));
  }
}

CameraRead V4l2Camera::next_frame(CameraFrame& out, double timeout_s) {
  if (state_ == CameraState::Stopped) {
    last_error_ = error_text("not streaming (call start())", 0);
    return CameraRead::Error;
  }
  const Deadline deadline(clock_, timeout_s);
  for (;;) {
    if (state_ == CameraState::Reconnecting && !try_reconnect(deadline)) return CameraRead::Timeout;
    if (held_ >= 0) {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = static_cast<std::uint32_t>(held_);
      held_ = -1;
      if (sys_.ioctl(fd_, VIDIOC_QBUF, &b) < 0) return lose_device(errno);
    }
    pollfd p{fd_, POLLIN, 0};
    const int ready = sys_.poll(&p, 1, deadline.remaining_ms());
    if (ready < 0) {
      if (errno == EINTR) continue;
      return lose_device(errno);
    }
    if (ready == 0) return CameraRead::Timeout;
    // With buffers queued, POLLERR means the device stopped being able to stream: it went away.
    if (p.revents & (POLLERR | POLLHUP | POLLNVAL)) return lose_device(ENODEV);

    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (sys_.ioctl(fd_, VIDIOC_DQBUF, &b) < 0) {
      const int error = errno;
      if (error == EAGAIN || error == EINTR) {
        if (deadline.expired()) return CameraRead::Timeout;
        continue;
      }
      return lose_device(device_gone(error) ? error : EIO);
    }
    if (b.index >= buffers_.size()) return lose_device(EIO);  // a driver bug: start over
    held_ = static_cast<int>(b.index);
    const std::size_t image_bytes = static_cast<std::size_t>(format_.stride_bytes) * static_cast<std::size_t>(format_.height);
    const bool compressed = bytes_per_pixel(format_.format) == 0;
    if ((b.flags & V4L2_BUF_FLAG_ERROR) || b.bytesused > buffers_[held_].length ||
        (!compressed && b.bytesused < image_bytes) || b.bytesused == 0) {
      ++stats_.corrupt_frames;  // requeued at the top of the loop
      continue;
    }
    if (have_sequence_) stats_.dropped_frames += static_cast<std::uint32_t>(b.sequence - last_sequence_ - 1);
    have_sequence_ = true;
    last_sequence_ = b.sequence;

    out = format_;
    out.data = static_cast<const std::uint8_t*>(buffers_[held_].address);
    out.size_bytes = compressed ? b.bytesused : image_bytes;
    out.sequence = b.sequence;
    const bool monotonic = (b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
    if (monotonic && (b.timestamp.tv_sec != 0 || b.timestamp.tv_usec != 0)) {
      out.t_s = static_cast<double>(b.timestamp.tv_sec) + static_cast<double>(b.timestamp.tv_usec) * 1e-6;
    } else {
      out.t_s = clock_.now_s();
      ++stats_.unstamped_frames;
    }
    ++stats_.frames;
    return CameraRead::Frame;
  }
}

}  // namespace epichead::hw
