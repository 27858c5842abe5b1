#include <cerrno>
#include <cstring>

#include "gpiod_line.h"

namespace epichead::hw {

std::expected<std::unique_ptr<GpiodLine>, std::string> request_gpiod_line(const GpioLineOptions& options,
                                                                          int request_type, int default_value) {
  const std::string name = "GPIO " + options.chip + " line " + std::to_string(options.offset);
  gpiod_chip* chip = gpiod_chip_open_lookup(options.chip.c_str());
  if (chip == nullptr) {
    // open_lookup tries name, path, number and label; errno is from the last try.
    std::string message = "GPIO chip '" + options.chip + "': cannot open: " + std::strerror(errno);
    if (errno == ENOENT) message += " (no such chip; `gpiodetect` lists them)";
    return std::unexpected(message);
  }
  const unsigned lines = gpiod_chip_num_lines(chip);
  if (options.offset >= lines) {
    gpiod_chip_close(chip);
    return std::unexpected(name + ": no such line (the chip has " + std::to_string(lines) + ")");
  }
  gpiod_line* line = gpiod_chip_get_line(chip, options.offset);
  if (line == nullptr) {
    const int error = errno;
    gpiod_chip_close(chip);
    return std::unexpected(name + ": cannot get the line: " + std::strerror(error));
  }
  gpiod_line_request_config config{};
  config.consumer = options.consumer.c_str();
  config.request_type = request_type;
  config.flags = options.active_low ? GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW : 0;
  if (gpiod_line_request(line, &config, default_value) < 0) {
    const int error = errno;
    std::string message = name + ": cannot request the line: " + std::strerror(error);
    if (error == EBUSY) {
      const char* user = gpiod_line_consumer(line);
      message += std::string(" (in use by '") + (user != nullptr ? user : "?") + "')";
    }
    gpiod_chip_close(chip);
    return std::unexpected(message);
  }
  return std::make_unique<GpiodLine>(chip, line, name);
}

}  // namespace epichead::hw
