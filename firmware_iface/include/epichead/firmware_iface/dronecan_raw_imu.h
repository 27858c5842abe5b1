#pragma once
// DroneCAN (UAVCAN v0) uavcan.equipment.ahrs.RawIMU, for IMUs that speak DroneCAN on CAN
// instead of our own frames (imu_protocol.h selects which). A RawIMU transfer is 47 bytes
// plus an optional float16 covariance, so on classic CAN it is a multi-frame transfer: 29-bit
// id (priority, data type id 1003, source node), payload frames of up to 7 bytes, each ended
// by a tail byte (start, end, toggle, 5-bit transfer id); the first frame begins with the
// transfer CRC (CRC-16-CCITT-FALSE over the data type signature, little-endian, then the
// payload). The message's body frame is X forward, Y right, Z down; the decoder returns our
// camera axes (x right, y down, z forward): ours = (Y, Z, X).
#include <array>
#include <cstddef>
#include <cstdint>
#include <expected>
#include <optional>
#include <vector>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/firmware_iface/wire_error.h"

namespace epichead::firmware_iface {

inline constexpr std::uint16_t kRawImuDataTypeId = 1003;
inline constexpr std::uint64_t kRawImuSignature = 0x8280632C40E574B5ULL;
inline constexpr std::size_t kRawImuFixedBytes = 47;   // without the covariance
inline constexpr std::size_t kRawImuMaxCovariance = 36;
inline constexpr std::int64_t kDroneCanTransferTimeoutUs = 2'000'000;  // spec: 2 s

struct DroneCanRawImu {
  std::uint8_t source_node = 0;
  std::uint8_t transfer_id = 0;
  std::uint64_t timestamp_us = 0;  // uavcan.Timestamp, uint56, the bus's shared time base
  float integration_interval_s = 0;
  std::array<double, 3> gyro_radps{};     // latest sample, our axes
  std::array<double, 3> accel_mps2{};     // latest sample, our axes
  std::array<double, 3> gyro_integral{};  // integrated samples as sent, our axes
  std::array<double, 3> accel_integral{};
  std::uint8_t covariance_count = 0;      // float16 entries present (0..36); values not kept
};

// Whether a frame is a RawIMU message frame (29-bit, message, data type 1003).
bool is_dronecan_raw_imu_frame(const CanFrame& frame);

// CRC-16-CCITT-FALSE (poly 0x1021, init 0xFFFF) of a DroneCAN transfer: signature first.
std::uint16_t dronecan_transfer_crc(std::uint64_t data_type_signature, const std::uint8_t* payload,
                                    std::size_t size);

// IEEE 754 half precision <-> float, written out because GCC 12's C++23 library has no
// std::float16_t and no Debian library offers a two-line conversion worth a dependency.
float half_to_float(std::uint16_t h);
std::uint16_t float_to_half(float f);  // round to nearest even, overflow to infinity

// Reassembles RawIMU transfers from any number of source nodes at once. State is sized at
// construction (one buffer per node id); push() does not allocate.
class DroneCanRawImuDecoder {
 public:
  DroneCanRawImuDecoder();

  // Feeds one frame (with its receive time, for the transfer timeout). Returns the sample when
  // the frame completes a valid transfer, nothing when the frame was accepted but the transfer
  // is not complete (or the frame is not RawIMU), or why the frame or transfer was rejected
  // (bad toggle, unexpected transfer id, CRC mismatch, wrong payload size).
  std::expected<std::optional<DroneCanRawImu>, WireError> push(const StampedCanFrame& frame);

  std::uint64_t transfers_timed_out() const { return timed_out_; }

 private:
  struct Assembly {
    bool active = false;
    std::uint8_t transfer_id = 0;
    bool next_toggle = false;
    std::uint16_t crc = 0;
    std::int64_t started_us = 0;
    std::size_t size = 0;
    std::array<std::uint8_t, kRawImuFixedBytes + 2 * kRawImuMaxCovariance> payload{};
  };
  std::vector<Assembly> nodes_;  // indexed by source node id 0..127
  std::uint64_t timed_out_ = 0;
};

// Decodes a complete RawIMU payload (no CRC) into our axes.
std::expected<DroneCanRawImu, WireError> decode_raw_imu_payload(const std::uint8_t* payload, std::size_t size);

// Splits a RawIMU message into frames (simulator, tests): data type 1003, the given node,
// transfer id and priority (0 highest .. 31). Values are converted back to the FRD body frame.
std::vector<CanFrame> encode_dronecan_raw_imu(const DroneCanRawImu& m, std::uint8_t source_node,
                                              std::uint8_t transfer_id, std::uint8_t priority = 16);

}  // namespace epichead::firmware_iface
