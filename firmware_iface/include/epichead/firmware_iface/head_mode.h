#pragma once
// The head's control mode, commanded by the controller and echoed in the head's state.
#include <cstdint>
#include <string_view>

namespace epichead::firmware_iface {

enum class HeadMode : std::uint8_t {
  Off = 0,       // motors unpowered
  Position = 1,  // follow the commanded angles, rates as feed-forward
  Rate = 2,      // follow the commanded rates, angles ignored
  SafeStop = 3,  // brake to rest and hold (also entered by the head on command timeout)
};
inline constexpr std::uint8_t kHeadModeCount = 4;

std::string_view to_string(HeadMode mode);

}  // namespace epichead::firmware_iface
