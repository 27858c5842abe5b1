#pragma once
// Which GPIO line a libgpiod driver uses: chip, offset and how it is requested.
#include <string>

namespace epichead::hw {

struct GpioLineOptions {
  std::string chip = "gpiochip0";     // name, /dev path, number or label (gpiod_chip_open_lookup)
  unsigned offset = 0;                // line number on the chip
  std::string consumer = "epichead";  // shown by gpioinfo as the line's user
  bool active_low = false;            // Active drives (or reads) the line low
};

}  // namespace epichead::hw
