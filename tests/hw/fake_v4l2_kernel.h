#pragma once
// A stand-in for a V4L2 capture driver behind the Syscalls interface: one device node that can
// be unplugged and plugged back, a list of supported formats, mmap buffers in test memory, and
// a frame produced whenever the driver has a queued buffer and the test lets it (poll/DQBUF).
// poll() with no descriptors advances the fake clock (the camera's sleep between reconnects).
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <deque>
#include <string>
#include <vector>

#include "epichead/hw/fake_clock.h"
#include "epichead/hw/syscalls.h"

namespace epichead::testing {

class FakeV4l2Kernel : public hw::Syscalls {
 public:
  explicit FakeV4l2Kernel(hw::FakeClock& clock) : clock_(clock) {}

  std::string path = "/dev/video7";
  bool present = true;                 // unplugged: open fails, the open fd fails with ENODEV
  bool capture_device = true;
  std::vector<std::uint32_t> formats = {V4L2_PIX_FMT_YUYV};
  std::uint32_t width = 320, height = 240;
  std::uint32_t stride_padding = 0;    // extra bytes per row
  int frames_available = 0;            // frames the "sensor" will still deliver
  std::deque<std::uint32_t> bad_frames;  // sequence numbers delivered with V4L2_BUF_FLAG_ERROR
  std::uint32_t skip_before_next = 0;  // sequence numbers lost before the next frame
  bool monotonic_stamps = true;
  int opens = 0, closes = 0, mapped = 0, streamons = 0;

  int open(const char* p, int) override {
    if (!present || path != p) return fail(ENOENT);
    ++opens;
    fd_ = 100 + opens;
    streaming_ = false;
    buffers_.clear();
    queued_.clear();
    return fd_;
  }
  int close(int fd) override {
    if (fd == fd_) fd_ = -1;
    ++closes;
    return 0;
  }
  void* mmap(std::size_t length, int, int, int fd, off_t offset) override {
    if (!present || fd != fd_) return fail_map(ENODEV);
    const std::size_t index = static_cast<std::size_t>(offset) / kPage;
    if (index >= buffers_.size() || length != buffers_[index].size()) return fail_map(EINVAL);
    ++mapped;
    return buffers_[index].data();
  }
  int munmap(void*, std::size_t) override {
    --mapped;
    return 0;
  }
  int poll(pollfd* fds, nfds_t count, int timeout_ms) override {
    if (count == 0) {  // a sleep
      clock_.advance(timeout_ms * 1e-3);
      return 0;
    }
    fds[0].revents = 0;
    if (!present) fds[0].revents = POLLERR;
    else if (streaming_ && !queued_.empty() && frames_available > 0) fds[0].revents = POLLIN;
    if (fds[0].revents == 0) {
      clock_.advance(std::max(timeout_ms, 0) * 1e-3);  // waited the whole timeout for nothing
      return 0;
    }
    return 1;
  }
  int ioctl(int fd, unsigned long request, void* arg) override {
    if (fd != fd_) return fail(EBADF);
    if (!present) return fail(ENODEV);
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* cap = static_cast<v4l2_capability*>(arg);
        *cap = {};
        std::strcpy(reinterpret_cast<char*>(cap->driver), "fake");
        cap->device_caps = (capture_device ? V4L2_CAP_VIDEO_CAPTURE : V4L2_CAP_VIDEO_OUTPUT) | V4L2_CAP_STREAMING;
        cap->capabilities = cap->device_caps | V4L2_CAP_DEVICE_CAPS;
        return 0;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        if (d->index >= formats.size()) return fail(EINVAL);
        d->pixelformat = formats[d->index];
        return 0;
      }
      case VIDIOC_S_FMT: {
        auto* f = static_cast<v4l2_format*>(arg);
        // Like real drivers: a format it lacks is replaced by its first one; the size is its own.
        if (std::find(formats.begin(), formats.end(), f->fmt.pix.pixelformat) == formats.end()) {
          f->fmt.pix.pixelformat = formats.front();
        }
        f->fmt.pix.width = width;
        f->fmt.pix.height = height;
        const std::uint32_t bpp = f->fmt.pix.pixelformat == V4L2_PIX_FMT_GREY ? 1 : 2;
        f->fmt.pix.bytesperline = width * bpp + stride_padding;
        f->fmt.pix.sizeimage = f->fmt.pix.bytesperline * height;
        sizeimage_ = f->fmt.pix.sizeimage;
        return 0;
      }
      case VIDIOC_REQBUFS: {
        auto* r = static_cast<v4l2_requestbuffers*>(arg);
        if (r->memory != V4L2_MEMORY_MMAP) return fail(EINVAL);
        buffers_.assign(r->count, std::vector<std::uint8_t>(sizeimage_));
        queued_.clear();
        queued_.reserve(r->count);  // so QBUF/DQBUF never allocate (allocation-counting tests)
        return 0;
      }
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        b->length = static_cast<std::uint32_t>(buffers_[b->index].size());
        b->m.offset = b->index * kPage;
        return 0;
      }
      case VIDIOC_QBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        if (b->index >= buffers_.size()) return fail(EINVAL);
        if (std::find(queued_.begin(), queued_.end(), b->index) != queued_.end()) return fail(EINVAL);
        queued_.push_back(b->index);
        return 0;
      }
      case VIDIOC_STREAMON:
        streaming_ = true;
        ++streamons;
        return 0;
      case VIDIOC_STREAMOFF:
        streaming_ = false;
        queued_.clear();
        return 0;
      case VIDIOC_DQBUF: {
        if (!streaming_ || queued_.empty() || frames_available <= 0) return fail(EAGAIN);
        auto* b = static_cast<v4l2_buffer*>(arg);
        const std::uint32_t index = queued_.front();
        queued_.erase(queued_.begin());
        --frames_available;
        sequence_ += skip_before_next;
        skip_before_next = 0;
        b->index = index;
        b->sequence = sequence_;
        b->bytesused = sizeimage_;
        b->flags = monotonic_stamps ? V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC : V4L2_BUF_FLAG_TIMESTAMP_UNKNOWN;
        if (!bad_frames.empty() && bad_frames.front() == sequence_) {
          bad_frames.pop_front();
          b->flags |= V4L2_BUF_FLAG_ERROR;
        }
        const double t_s = 1000.0 + sequence_ / 30.0;
        b->timestamp.tv_sec = static_cast<time_t>(t_s);
        b->timestamp.tv_usec = static_cast<suseconds_t>((t_s - static_cast<double>(b->timestamp.tv_sec)) * 1e6);
        std::fill(buffers_[index].begin(), buffers_[index].end(), static_cast<std::uint8_t>(sequence_));
        ++sequence_;
        return 0;
      }
      default:
        return fail(ENOTTY);
    }
  }

  std::size_t queued() const { return queued_.size(); }

 private:
  static constexpr std::size_t kPage = 4096;
  static int fail(int error) {
    errno = error;
    return -1;
  }
  static void* fail_map(int error) {
    errno = error;
    return MAP_FAILED;
  }
  hw::FakeClock& clock_;
  int fd_ = -1;
  bool streaming_ = false;
  std::uint32_t sizeimage_ = 0;
  std::uint32_t sequence_ = 0;
  std::vector<std::vector<std::uint8_t>> buffers_;
  std::vector<std::uint32_t> queued_;
};

}  // namespace epichead::testing
