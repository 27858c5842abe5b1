#pragma once
// A digital output port (the camera trigger): set the line's logical level. "Active" is the
// asserted level; whether that is high or low on the wire is the driver's configuration.
#include <expected>
#include <string>

namespace epichead::hw {

enum class GpioLevel { Inactive, Active };

class GpioOutput {
 public:
  virtual ~GpioOutput() = default;
  virtual std::expected<void, std::string> set(GpioLevel level) = 0;
};

}  // namespace epichead::hw
