#pragma once
// Versions of the program and of the wire protocol it speaks with the IMU and head firmware.
#include <cstdint>
#include <string_view>

namespace epichead::firmware_iface {

// Bumped when a frame layout on the bus changes incompatibly.
inline constexpr std::uint8_t kProtocolVersion = 1;

// The program's version, "major.minor.patch", from the build.
std::string_view program_version();

}  // namespace epichead::firmware_iface
