#pragma once
// A stand-in for the kernel's SocketCAN calls: scripted socket/ioctl/setsockopt/bind results,
// a queue of received frames with the control messages the kernel would attach, and a record
// of what was written.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/time.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <map>
#include <optional>
#include <vector>

#include "epichead/hw/syscalls.h"

namespace epichead::testing {

struct KernelDelivery {
  canfd_frame frame{};
  std::size_t nbytes = CAN_MTU;
  std::optional<timeval> stamp;
  std::optional<std::uint32_t> dropped_total;
  int error = 0;  // nonzero: recvmsg fails with this errno instead
};

class FakeCanKernel : public hw::Syscalls {
 public:
  int socket_errno = 0, ifindex_errno = 0, bind_errno = 0, write_errno = 0;
  std::map<int, int> setsockopt_errno;  // option name -> errno
  std::map<int, std::vector<unsigned char>> options;  // option name -> value set
  std::deque<KernelDelivery> queue;
  struct Written {
    canfd_frame frame{};
    std::size_t size = 0;
  };
  std::vector<Written> written;  // reserve() it to keep writes allocation-free
  int closed = 0, polls = 0;
  int bound_ifindex = -1;

  static constexpr int kFd = 42;

  int socket(int domain, int type, int protocol) override {
    if (socket_errno) return fail(socket_errno);
    if (domain != PF_CAN || (type & SOCK_RAW) == 0 || protocol != CAN_RAW) return fail(EINVAL);
    nonblocking = (type & SOCK_NONBLOCK) != 0;
    return kFd;
  }
  int ioctl(int fd, unsigned long request, void* arg) override {
    if (fd != kFd || request != SIOCGIFINDEX) return fail(ENOTTY);
    if (ifindex_errno) return fail(ifindex_errno);
    static_cast<ifreq*>(arg)->ifr_ifindex = 7;
    return 0;
  }
  int setsockopt(int, int, int name, const void* value, socklen_t length) override {
    if (auto it = setsockopt_errno.find(name); it != setsockopt_errno.end()) return fail(it->second);
    const auto* bytes = static_cast<const unsigned char*>(value);
    options[name].assign(bytes, bytes + length);
    return 0;
  }
  int bind(int, const sockaddr* address, socklen_t) override {
    if (bind_errno) return fail(bind_errno);
    bound_ifindex = reinterpret_cast<const sockaddr_can*>(address)->can_ifindex;
    return 0;
  }
  int close(int fd) override {
    if (fd == kFd) ++closed;
    return 0;
  }
  int poll(pollfd* fds, nfds_t, int) override {
    ++polls;
    if (stuck_pollerr) {  // a socket reporting an error that recvmsg never returns
      fds[0].revents = POLLERR;
      return 1;
    }
    fds[0].revents = queue.empty() ? 0 : POLLIN;
    return queue.empty() ? 0 : 1;
  }
  ssize_t recvmsg(int, msghdr* message, int) override {
    if (queue.empty()) return fail(EAGAIN);
    const KernelDelivery d = queue.front();
    queue.pop_front();
    if (d.error) return fail(d.error);
    std::memcpy(message->msg_iov[0].iov_base, &d.frame, std::min(d.nbytes, sizeof d.frame));
    // Control messages laid out as the kernel does (CMSG_* macros).
    std::size_t used = 0;
    auto* control = static_cast<unsigned char*>(message->msg_control);
    auto add = [&](int type, const void* data, std::size_t size) {
      auto* c = reinterpret_cast<cmsghdr*>(control + used);
      c->cmsg_level = SOL_SOCKET;
      c->cmsg_type = type;
      c->cmsg_len = CMSG_LEN(size);
      std::memcpy(CMSG_DATA(c), data, size);
      used += CMSG_SPACE(size);
    };
    if (d.stamp) add(SCM_TIMESTAMP, &*d.stamp, sizeof(timeval));
    if (d.dropped_total) add(SO_RXQ_OVFL, &*d.dropped_total, sizeof(std::uint32_t));
    message->msg_controllen = used;
    return static_cast<ssize_t>(d.nbytes);
  }
  ssize_t write(int, const void* data, std::size_t size) override {
    if (write_errno) return fail(write_errno);
    Written w;
    std::memcpy(&w.frame, data, std::min(size, sizeof w.frame));
    w.size = size;
    written.push_back(w);
    return static_cast<ssize_t>(size);
  }

  void push(canid_t id, std::initializer_list<std::uint8_t> data, std::optional<timeval> stamp = std::nullopt,
            std::optional<std::uint32_t> dropped_total = std::nullopt) {
    KernelDelivery d;
    d.frame.can_id = id;
    d.frame.len = static_cast<std::uint8_t>(data.size());
    std::copy(data.begin(), data.end(), d.frame.data);
    d.stamp = stamp;
    d.dropped_total = dropped_total;
    queue.push_back(d);
  }

  bool nonblocking = false;
  bool stuck_pollerr = false;

 private:
  static int fail(int error) {
    errno = error;
    return -1;
  }
};

}  // namespace epichead::testing
