#include <gpiod.h>

#include <cerrno>
#include <cstring>

#include "epichead/hw/gpio_event_fd_reader.h"
#include "deadline.h"

namespace epichead::hw {

GpioEventFdReader::GpioEventFdReader(int fd, std::string name, Syscalls& sys, Clock& clock)
    : fd_(fd), name_(std::move(name)), sys_(sys), clock_(clock) {}

GpioWait GpioEventFdReader::fail(const char* what, int error) {
  last_error_ = name_ + ": " + what + ": " + std::strerror(error);
  return GpioWait::Error;
}

GpioWait GpioEventFdReader::wait(GpioEdge& out, double timeout_s) {
  const Deadline deadline(clock_, timeout_s);
  for (;;) {
    pollfd p{fd_, POLLIN, 0};
    const int ready = sys_.poll(&p, 1, deadline.remaining_ms());
    if (ready < 0) {
      if (errno == EINTR) continue;
      return fail("poll failed", errno);
    }
    if (ready == 0) return GpioWait::Timeout;
    if (p.revents & POLLNVAL) return fail("poll failed", EBADF);
    if ((p.revents & POLLIN) == 0) return fail("event descriptor failed", (p.revents & POLLHUP) ? ENODEV : EIO);
    // libgpiod reads one gpioevent_data and fails with EIO on a short read (garbage).
    gpiod_line_event event{};
    if (gpiod_line_event_read_fd(fd_, &event) < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return fail("cannot read an edge event", errno);
    }
    out.t_s = static_cast<double>(event.ts.tv_sec) + static_cast<double>(event.ts.tv_nsec) * 1e-9;  // as clock.cpp
    out.kind = event.event_type == GPIOD_LINE_EVENT_FALLING_EDGE ? GpioEdgeKind::Falling : GpioEdgeKind::Rising;
    ++edges_;
    return GpioWait::Edge;
  }
}

}  // namespace epichead::hw
