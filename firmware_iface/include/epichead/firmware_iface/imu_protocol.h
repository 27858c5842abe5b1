#pragma once
// Which protocol the IMU on the bus speaks: the configuration's `imu_protocol` key.
#include <cstdint>
#include <expected>
#include <string>
#include <string_view>

namespace epichead::firmware_iface {

enum class ImuProtocol : std::uint8_t {
  Epichead,        // our ImuGyro / ImuAccel frames (imu_frames.h)
  DroneCanRawImu,  // uavcan.equipment.ahrs.RawIMU (dronecan_raw_imu.h)
};

// "epichead" or "dronecan"; anything else is an error naming the accepted values.
std::expected<ImuProtocol, std::string> parse_imu_protocol(std::string_view text);
std::string_view to_string(ImuProtocol protocol);

}  // namespace epichead::firmware_iface
