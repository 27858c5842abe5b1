#include "epichead/hw/gpiod_edge_input.h"
#include "gpiod_line.h"

namespace epichead::hw {

GpiodEdgeInput::GpiodEdgeInput(std::unique_ptr<GpiodLine> line, int fd, Clock& clock)
    : line_(std::move(line)), reader_(fd, line_->name(), Syscalls::real(), clock) {}
GpiodEdgeInput::~GpiodEdgeInput() = default;

std::expected<std::unique_ptr<GpiodEdgeInput>, std::string> GpiodEdgeInput::open(const GpioLineOptions& options,
                                                                                 GpioEdges edges, Clock& clock) {
  const int type = edges == GpioEdges::Rising    ? GPIOD_LINE_REQUEST_EVENT_RISING_EDGE
                   : edges == GpioEdges::Falling ? GPIOD_LINE_REQUEST_EVENT_FALLING_EDGE
                                                 : GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES;
  auto line = request_gpiod_line(options, type, 0);
  if (!line) return std::unexpected(line.error());
  const int fd = gpiod_line_event_get_fd((*line)->line());
  if (fd < 0) return std::unexpected((*line)->name() + ": the line has no event descriptor");
  return std::unique_ptr<GpiodEdgeInput>(new GpiodEdgeInput(std::move(*line), fd, clock));
}

}  // namespace epichead::hw
