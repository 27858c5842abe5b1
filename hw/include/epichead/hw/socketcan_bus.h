#pragma once
// CanBus over Linux SocketCAN: a non-blocking CAN_RAW socket bound to one interface, with id
// filters, error frames, kernel receive time stamps (SO_TIMESTAMP, wall clock in µs like
// candump), the kernel's drop counter (SO_RXQ_OVFL) and a receive queue sized for stalls.
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include "epichead/hw/can_bus.h"
#include "epichead/hw/clock.h"
#include "epichead/hw/socketcan_frames.h"
#include "epichead/hw/syscalls.h"

namespace epichead::hw {

struct SocketCanOptions {
  std::string interface = "can0";
  std::vector<CanIdFilter> filters;     // empty: receive every frame
  bool error_frames = true;             // subscribe to all error classes (bus-off, passive, ...)
  bool fd_frames = false;               // also receive and allow sending CAN FD frames
  // The kernel's receive queue. Its default (net.core.rmem_default, about 200 KiB: some 250
  // frames) bridges only ~0.1 s at the IMU's 2000 frames/s when the reader stalls. Asked with
  // SO_RCVBUFFORCE (CAP_NET_ADMIN), else SO_RCVBUF, which the kernel caps at
  // net.core.rmem_max. 0 keeps the kernel's default.
  int receive_buffer_bytes = 1 << 20;
};

class SocketCanBus final : public CanBus {
 public:
  // Opens and binds the socket; the error names the interface and what failed.
  // `clock` measures the receive timeout; `sys` is the kernel (tests pass a fake).
  static std::expected<std::unique_ptr<SocketCanBus>, std::string> open(
      const SocketCanOptions& options, Syscalls& sys = Syscalls::real(), Clock& clock = monotonic_clock());
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  std::expected<void, std::string> send(const CanFrame& frame) override;
  CanReceive receive(StampedCanFrame& out, double timeout_s) override;
  CanBusStats stats() const override { return stats_; }
  std::string_view last_error() const override { return last_error_; }

 private:
  SocketCanBus(std::string interface, int fd, Syscalls& sys, Clock& clock);
  // One non-blocking read: Frame, Timeout (nothing queued) or Error.
  CanReceive read_one(StampedCanFrame& out);
  CanReceive fail(const char* what, int error);

  std::string interface_;
  int fd_;
  Syscalls& sys_;
  Clock& clock_;
  CanBusStats stats_;
  std::uint32_t dropped_seen_ = 0;  // last SO_RXQ_OVFL total, to count the increase
  std::string last_error_;
};

}  // namespace epichead::hw
