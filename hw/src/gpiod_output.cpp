#include <cerrno>
#include <cstring>

#include "epichead/hw/gpiod_output.h"
#include "gpiod_line.h"

namespace epichead::hw {

GpiodOutput::GpiodOutput(std::unique_ptr<GpiodLine> line) : line_(std::move(line)) {}
GpiodOutput::~GpiodOutput() = default;

std::expected<std::unique_ptr<GpiodOutput>, std::string> GpiodOutput::open(const GpioLineOptions& options,
                                                                           GpioLevel initial) {
  auto line = request_gpiod_line(options, GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, initial == GpioLevel::Active ? 1 : 0);
  if (!line) return std::unexpected(line.error());
  return std::unique_ptr<GpiodOutput>(new GpiodOutput(std::move(*line)));
}

std::expected<void, std::string> GpiodOutput::set(GpioLevel level) {
  if (gpiod_line_set_value(line_->line(), level == GpioLevel::Active ? 1 : 0) < 0) {
    return std::unexpected(line_->name() + ": cannot set the level: " + std::strerror(errno));
  }
  return {};
}

}  // namespace epichead::hw
