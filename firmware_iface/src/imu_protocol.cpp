#include "epichead/firmware_iface/imu_protocol.h"

namespace epichead::firmware_iface {

std::expected<ImuProtocol, std::string> parse_imu_protocol(std::string_view text) {
  if (text == "epichead") return ImuProtocol::Epichead;
  if (text == "dronecan") return ImuProtocol::DroneCanRawImu;
  return std::unexpected("imu_protocol '" + std::string(text) + "': expected 'epichead' or 'dronecan'");
}

std::string_view to_string(ImuProtocol protocol) {
  return protocol == ImuProtocol::Epichead ? "epichead" : "dronecan";
}

}  // namespace epichead::firmware_iface
