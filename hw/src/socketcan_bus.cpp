#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <time.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "epichead/hw/socketcan_bus.h"
#include "deadline.h"

namespace epichead::hw {
namespace {

std::string open_error(const std::string& interface, const char* what, int error) {
  std::string message = "SocketCAN interface '" + interface + "': " + what + ": " + std::strerror(error);
  if (error == EAFNOSUPPORT || error == EPROTONOSUPPORT) {
    message += " (this kernel has no CAN support; load the can and can_raw modules)";
  } else if (error == ENODEV) {
    message += " (no such network interface; `ip link` lists them)";
  }
  return message;
}

std::int64_t wall_clock_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000 + ts.tv_nsec / 1000;
}

}  // namespace

std::expected<std::unique_ptr<SocketCanBus>, std::string> SocketCanBus::open(const SocketCanOptions& options,
                                                                             Syscalls& sys, Clock& clock) {
  const std::string& name = options.interface;
  if (name.empty() || name.size() >= IFNAMSIZ) {
    return std::unexpected("SocketCAN interface '" + name + "': name must have 1 to " +
                           std::to_string(IFNAMSIZ - 1) + " characters");
  }
  const int fd = sys.socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) return std::unexpected(open_error(name, "cannot create a CAN_RAW socket", errno));
  // From here on the bus owns fd, so every early return closes it.
  std::unique_ptr<SocketCanBus> bus(new SocketCanBus(name, fd, sys, clock));

  ifreq request{};
  std::memcpy(request.ifr_name, name.data(), name.size());
  if (sys.ioctl(fd, SIOCGIFINDEX, &request) < 0) return std::unexpected(open_error(name, "no such interface", errno));

  std::vector<can_filter> filters;
  filters.reserve(options.filters.size());
  for (const CanIdFilter& f : options.filters) filters.push_back(to_kernel_filter(f));
  if (!filters.empty() && sys.setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                                         static_cast<socklen_t>(filters.size() * sizeof(can_filter))) < 0) {
    return std::unexpected(open_error(name, "cannot set the receive filters", errno));
  }
  const can_err_mask_t error_mask = options.error_frames ? CAN_ERR_MASK : 0;
  if (sys.setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &error_mask, sizeof error_mask) < 0) {
    return std::unexpected(open_error(name, "cannot subscribe to error frames", errno));
  }
  const int on = 1;
  if (options.fd_frames && sys.setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0) {
    return std::unexpected(open_error(name, "cannot enable CAN FD frames", errno));
  }
  if (sys.setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on) < 0) {
    return std::unexpected(open_error(name, "cannot enable receive time stamps (SO_TIMESTAMP)", errno));
  }
  if (sys.setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on) < 0) {
    return std::unexpected(open_error(name, "cannot enable the drop counter (SO_RXQ_OVFL)", errno));
  }
  if (options.receive_buffer_bytes < 0) {
    return std::unexpected("SocketCAN interface '" + name + "': receive_buffer_bytes must be >= 0");
  }
  if (options.receive_buffer_bytes > 0) {
    const int bytes = options.receive_buffer_bytes;
    // Without CAP_NET_ADMIN the forced size is refused and the plain one is capped, not refused.
    if (sys.setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &bytes, sizeof bytes) < 0 &&
        sys.setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &bytes, sizeof bytes) < 0) {
      return std::unexpected(open_error(name, "cannot size the receive queue (SO_RCVBUF)", errno));
    }
  }
  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = request.ifr_ifindex;
  if (sys.bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) < 0) {
    return std::unexpected(open_error(name, "cannot bind", errno));
  }
  return bus;
}

SocketCanBus::SocketCanBus(std::string interface, int fd, Syscalls& sys, Clock& clock)
    : interface_(std::move(interface)), fd_(fd), sys_(sys), clock_(clock) {}

SocketCanBus::~SocketCanBus() { sys_.close(fd_); }

std::expected<void, std::string> SocketCanBus::send(const CanFrame& frame) {
  canfd_frame kernel;
  const auto size = to_kernel_frame(frame, kernel);
  if (!size) {
    ++stats_.tx_failed;
    return std::unexpected(interface_ + ": " + size.error());
  }
  const ssize_t written = sys_.write(fd_, &kernel, *size);
  if (written != static_cast<ssize_t>(*size)) {
    const int error = written < 0 ? errno : EIO;
    ++stats_.tx_failed;
    char id[16];
    std::snprintf(id, sizeof id, "0x%X", static_cast<unsigned>(frame.id));
    std::string message = interface_ + ": send of CAN id " + id + " failed: " + std::strerror(error);
    if (error == ENOBUFS || error == EAGAIN) message += " (transmit queue full)";
    if (error == EINVAL && frame.fd()) message += " (CAN FD not enabled on the socket or interface)";
    return std::unexpected(message);
  }
  ++stats_.tx_frames;
  return {};
}

CanReceive SocketCanBus::fail(const char* what, int error) {
  last_error_ = interface_ + ": " + what + ": " + std::strerror(error);
  if (error == ENETDOWN) last_error_ += " (interface down)";
  return CanReceive::Error;
}

CanReceive SocketCanBus::read_one(StampedCanFrame& out) {
  canfd_frame kernel{};
  iovec io{&kernel, sizeof kernel};
  // Room for a time stamp and the drop counter, aligned for cmsghdr.
  alignas(cmsghdr) unsigned char control[CMSG_SPACE(sizeof(timespec)) + CMSG_SPACE(sizeof(std::uint32_t)) + 64];
  for (;;) {
    msghdr message{};
    message.msg_iov = &io;
    message.msg_iovlen = 1;
    message.msg_control = control;
    message.msg_controllen = sizeof control;
    const ssize_t n = sys_.recvmsg(fd_, &message, MSG_DONTWAIT);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) return CanReceive::Timeout;
      return fail("receive failed", errno);
    }
    const CanReceiveMeta meta = parse_receive_meta(message);
    // SO_RXQ_OVFL is the socket's running total; unsigned difference survives its wrap.
    if (meta.dropped_total) {
      stats_.rx_dropped += static_cast<std::uint32_t>(*meta.dropped_total - dropped_seen_);
      dropped_seen_ = *meta.dropped_total;
    }
    auto frame = from_kernel_frame(kernel, static_cast<std::size_t>(n));
    if (!frame) {
      ++stats_.rx_malformed;  // counted and skipped: one bad read must not stop the bus
      continue;
    }
    out.frame = *frame;
    out.stamp_us = meta.stamp_us ? *meta.stamp_us : wall_clock_us();
    if (frame->error()) {
      ++stats_.rx_error_frames;
      const CanErrorReport report = classify_error_frame(*frame);
      if (report.state) {
        if (*report.state == CanBusState::BusOff && stats_.state != CanBusState::BusOff) ++stats_.bus_off_events;
        stats_.state = *report.state;
      }
    } else {
      ++stats_.rx_frames;
    }
    return CanReceive::Frame;
  }
}

CanReceive SocketCanBus::receive(StampedCanFrame& out, double timeout_s) {
  const Deadline deadline(clock_, timeout_s);
  bool polled = false;
  for (;;) {
    const CanReceive got = read_one(out);
    if (got != CanReceive::Timeout) return got;
    // Readable (or POLLERR) but nothing to read once the time is up: a timeout, not a spin.
    if (polled && deadline.expired()) return CanReceive::Timeout;
    pollfd p{fd_, POLLIN, 0};
    const int ready = sys_.poll(&p, 1, deadline.remaining_ms());
    if (ready < 0 && errno != EINTR) return fail("poll failed", errno);
    if (ready == 0) return CanReceive::Timeout;  // poll waited the remaining time
    if (ready > 0 && (p.revents & POLLNVAL)) return fail("poll failed", EBADF);
    // Readable, or an error pending (POLLERR: the next recvmsg reports it): read again.
    polled = true;
  }
}

}  // namespace epichead::hw
