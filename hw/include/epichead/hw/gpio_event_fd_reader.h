#pragma once
// Reads line events from a GPIO character-device event descriptor (the v1 uAPI that libgpiod
// 1.6 uses): poll with a deadline, then gpiod_line_event_read_fd. Separate from the libgpiod
// line handling so it runs on any descriptor, e.g. a pipe carrying gpioevent_data in a test.
#include <cstdint>
#include <string>
#include <string_view>

#include "epichead/hw/clock.h"
#include "epichead/hw/gpio_edge_input.h"
#include "epichead/hw/syscalls.h"

namespace epichead::hw {

class GpioEventFdReader {
 public:
  // `fd` is borrowed (the libgpiod line owns it); `name` appears in error messages.
  GpioEventFdReader(int fd, std::string name, Syscalls& sys = Syscalls::real(), Clock& clock = monotonic_clock());
  GpioWait wait(GpioEdge& out, double timeout_s);
  std::uint64_t edges() const { return edges_; }
  std::string_view last_error() const { return last_error_; }

 private:
  GpioWait fail(const char* what, int error);
  int fd_;
  std::string name_;
  Syscalls& sys_;
  Clock& clock_;
  std::uint64_t edges_ = 0;
  std::string last_error_;
};

}  // namespace epichead::hw
