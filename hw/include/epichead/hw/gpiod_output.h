#pragma once
// GpioOutput over libgpiod 1.6 (Debian bookworm): the camera trigger line. Opening fails with a
// message naming the chip and line when the chip, the line or the request is not available.
#include <expected>
#include <memory>
#include <string>

#include "epichead/hw/gpio_line_options.h"
#include "epichead/hw/gpio_output.h"

namespace epichead::hw {

class GpiodLine;  // src/gpiod_line.h: the chip and the requested line

class GpiodOutput final : public GpioOutput {
 public:
  static std::expected<std::unique_ptr<GpiodOutput>, std::string> open(const GpioLineOptions& options,
                                                                       GpioLevel initial = GpioLevel::Inactive);
  ~GpiodOutput() override;
  std::expected<void, std::string> set(GpioLevel level) override;

 private:
  explicit GpiodOutput(std::unique_ptr<GpiodLine> line);
  std::unique_ptr<GpiodLine> line_;
};

}  // namespace epichead::hw
