#pragma once
// GpioEdgeInput over libgpiod 1.6: the IMU sync input, with the kernel's edge time stamps
// (CLOCK_MONOTONIC since Linux 5.7). Opening fails with a message naming the chip and line.
#include <expected>
#include <memory>
#include <string>

#include "epichead/hw/clock.h"
#include "epichead/hw/gpio_edge_input.h"
#include "epichead/hw/gpio_event_fd_reader.h"
#include "epichead/hw/gpio_line_options.h"

namespace epichead::hw {

class GpiodLine;  // src/gpiod_line.h

enum class GpioEdges { Rising, Falling, Both };

class GpiodEdgeInput final : public GpioEdgeInput {
 public:
  static std::expected<std::unique_ptr<GpiodEdgeInput>, std::string> open(
      const GpioLineOptions& options, GpioEdges edges = GpioEdges::Rising, Clock& clock = monotonic_clock());
  ~GpiodEdgeInput() override;
  GpioWait wait_edge(GpioEdge& out, double timeout_s) override { return reader_.wait(out, timeout_s); }
  std::uint64_t edges() const override { return reader_.edges(); }
  std::string_view last_error() const override { return reader_.last_error(); }

 private:
  GpiodEdgeInput(std::unique_ptr<GpiodLine> line, int fd, Clock& clock);
  std::unique_ptr<GpiodLine> line_;
  GpioEventFdReader reader_;
};

}  // namespace epichead::hw
