#pragma once
// A libgpiod chip with one requested line, released together; and the request itself, whose
// errors name the chip and line ("GPIO gpiochip0 line 17: ...").
#include <gpiod.h>

#include <expected>
#include <memory>
#include <string>

#include "epichead/hw/gpio_line_options.h"

namespace epichead::hw {

class GpiodLine {
 public:
  GpiodLine(gpiod_chip* chip, gpiod_line* line, std::string name) : chip_(chip), line_(line), name_(std::move(name)) {}
  ~GpiodLine() {
    if (line_ != nullptr) gpiod_line_release(line_);
    if (chip_ != nullptr) gpiod_chip_close(chip_);
  }
  GpiodLine(const GpiodLine&) = delete;
  GpiodLine& operator=(const GpiodLine&) = delete;
  gpiod_line* line() const { return line_; }
  const std::string& name() const { return name_; }

 private:
  gpiod_chip* chip_;
  gpiod_line* line_;
  std::string name_;
};

// Opens the chip and requests the line as request_type (GPIOD_LINE_REQUEST_*), active-low if
// configured, with default_value for an output.
std::expected<std::unique_ptr<GpiodLine>, std::string> request_gpiod_line(const GpioLineOptions& options,
                                                                          int request_type, int default_value);

}  // namespace epichead::hw
