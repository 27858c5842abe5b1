#include "epichead/firmware_iface/dronecan_raw_imu.h"

#include <bit>
#include <cmath>
#include <algorithm>
#include <cstring>
#include <limits>

namespace epichead::firmware_iface {
namespace {

constexpr std::uint32_t kDataTypeShift = 8;
constexpr std::uint32_t kServiceBit = 1u << 7;
constexpr std::uint8_t kTailStart = 0x80, kTailEnd = 0x40, kTailToggle = 0x20, kTailTransferId = 0x1F;
constexpr std::size_t kMaxPayload = kRawImuFixedBytes + 2 * kRawImuMaxCovariance;

WireError transfer_error(const CanFrame& f, std::string_view what, std::int64_t value = 0) {
  return WireError{WireErrorKind::BadTransfer, f.id, f.len > 0 ? f.len - 1 : 0, what, value};
}

std::uint64_t get_le(const std::uint8_t* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}
float get_f32(const std::uint8_t* p) { return std::bit_cast<float>(static_cast<std::uint32_t>(get_le(p, 4))); }
float get_f16(const std::uint8_t* p) { return half_to_float(static_cast<std::uint16_t>(get_le(p, 2))); }
void put_le(std::vector<std::uint8_t>& out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
}

// FRD body (X forward, Y right, Z down) -> ours (x right, y down, z forward) and back.
std::array<double, 3> from_frd(float x, float y, float z) { return {y, z, x}; }
std::array<float, 3> to_frd(const std::array<double, 3>& v) {
  return {static_cast<float>(v[2]), static_cast<float>(v[0]), static_cast<float>(v[1])};
}

}  // namespace

bool is_dronecan_raw_imu_frame(const CanFrame& f) {
  return f.extended() && !f.remote() && !f.error() && (f.id & kServiceBit) == 0 &&
         ((f.id >> kDataTypeShift) & 0xFFFF) == kRawImuDataTypeId;
}

std::uint16_t dronecan_transfer_crc(std::uint64_t signature, const std::uint8_t* payload, std::size_t size) {
  std::uint16_t crc = 0xFFFF;
  const auto add = [&crc](std::uint8_t byte) {
    crc ^= static_cast<std::uint16_t>(byte << 8);
    for (int bit = 0; bit < 8; ++bit)
      crc = static_cast<std::uint16_t>((crc & 0x8000) ? (crc << 1) ^ 0x1021 : crc << 1);
  };
  for (int i = 0; i < 8; ++i) add(static_cast<std::uint8_t>(signature >> (8 * i)));
  for (std::size_t i = 0; i < size; ++i) add(payload[i]);
  return crc;
}

float half_to_float(std::uint16_t h) {
  const int sign = (h >> 15) & 1;
  const int exponent = (h >> 10) & 0x1F;
  const int mantissa = h & 0x3FF;
  float v;
  if (exponent == 0)
    v = std::ldexp(static_cast<float>(mantissa), -24);  // zero or subnormal
  else if (exponent == 31)
    v = mantissa ? std::numeric_limits<float>::quiet_NaN() : std::numeric_limits<float>::infinity();
  else
    v = std::ldexp(static_cast<float>(mantissa | 0x400), exponent - 25);
  return sign ? -v : v;
}

std::uint16_t float_to_half(float f) {
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(f);
  const std::uint16_t sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000);
  if (std::isnan(f)) return static_cast<std::uint16_t>(sign | 0x7E00);
  const float a = std::fabs(f);
  if (a >= 65520.0f) return static_cast<std::uint16_t>(sign | 0x7C00);  // rounds to infinity
  if (a < std::ldexp(1.0f, -14)) {  // subnormal: units of 2^-24, round to nearest even
    const float units = std::nearbyint(a * std::ldexp(1.0f, 24));
    return static_cast<std::uint16_t>(sign | static_cast<std::uint16_t>(units));
  }
  int exponent = 0;
  const float m = std::frexp(a, &exponent);  // a = m * 2^exponent, m in [0.5, 1)
  // 11 significant bits: mantissa in [1024, 2048).
  float significand = std::nearbyint(std::ldexp(m, 11));
  if (significand >= 2048.0f) {
    significand /= 2;
    ++exponent;
  }
  const int biased = exponent - 1 + 15;
  if (biased >= 31) return static_cast<std::uint16_t>(sign | 0x7C00);
  return static_cast<std::uint16_t>(sign | (biased << 10) | (static_cast<int>(significand) & 0x3FF));
}

std::expected<DroneCanRawImu, WireError> decode_raw_imu_payload(const std::uint8_t* p, std::size_t size) {
  if (size < kRawImuFixedBytes || size > kMaxPayload || (size - kRawImuFixedBytes) % 2 != 0)
    return std::unexpected(WireError{WireErrorKind::BadTransfer, kRawImuDataTypeId, -1, "payload size",
                                     static_cast<std::int64_t>(size)});
  DroneCanRawImu m;
  m.timestamp_us = get_le(p, 7);
  m.integration_interval_s = get_f32(p + 7);
  m.gyro_radps = from_frd(get_f16(p + 11), get_f16(p + 13), get_f16(p + 15));
  m.gyro_integral = from_frd(get_f32(p + 17), get_f32(p + 21), get_f32(p + 25));
  m.accel_mps2 = from_frd(get_f16(p + 29), get_f16(p + 31), get_f16(p + 33));
  m.accel_integral = from_frd(get_f32(p + 35), get_f32(p + 39), get_f32(p + 43));
  m.covariance_count = static_cast<std::uint8_t>((size - kRawImuFixedBytes) / 2);
  return m;
}

DroneCanRawImuDecoder::DroneCanRawImuDecoder() : nodes_(128) {}

std::expected<std::optional<DroneCanRawImu>, WireError> DroneCanRawImuDecoder::push(const StampedCanFrame& s) {
  const CanFrame& f = s.frame;
  if (!is_dronecan_raw_imu_frame(f)) return std::nullopt;
  if (f.len < 1) return std::unexpected(transfer_error(f, "tail byte missing"));
  const std::uint8_t source = f.id & 0x7F;
  const std::uint8_t tail = f.data[f.len - 1];
  const bool start = tail & kTailStart, end = tail & kTailEnd, toggle = tail & kTailToggle;
  const std::uint8_t tid = tail & kTailTransferId;
  const std::size_t body = f.len - 1u;
  Assembly& a = nodes_[source];

  if (a.active && s.stamp_us - a.started_us > kDroneCanTransferTimeoutUs) {
    a.active = false;
    ++timed_out_;
  }
  if (start) {
    if (toggle) return std::unexpected(transfer_error(f, "toggle set on first frame", tail));
    if (end) {  // single-frame transfer: no CRC
      auto m = decode_raw_imu_payload(f.data.data(), body);
      if (!m) return std::unexpected(transfer_error(f, "payload size", static_cast<std::int64_t>(body)));
      m->source_node = source;
      m->transfer_id = tid;
      return std::optional<DroneCanRawImu>(*m);
    }
    if (body < 2) return std::unexpected(transfer_error(f, "first frame without CRC", static_cast<std::int64_t>(body)));
    // A new start replaces an unfinished transfer from the same node (its frames were lost).
    a.active = true;
    a.transfer_id = tid;
    a.next_toggle = true;
    a.crc = static_cast<std::uint16_t>(f.data[0] | (f.data[1] << 8));
    a.started_us = s.stamp_us;
    a.size = body - 2;
    std::memcpy(a.payload.data(), f.data.data() + 2, a.size);
    return std::nullopt;
  }
  if (!a.active) return std::unexpected(transfer_error(f, "continuation without start", tid));
  if (tid != a.transfer_id || toggle != a.next_toggle) {
    a.active = false;
    return std::unexpected(transfer_error(f, tid != a.transfer_id ? "transfer id changed" : "toggle bit", tail));
  }
  if (a.size + body > a.payload.size()) {
    a.active = false;
    return std::unexpected(transfer_error(f, "payload too long", static_cast<std::int64_t>(a.size + body)));
  }
  std::memcpy(a.payload.data() + a.size, f.data.data(), body);
  a.size += body;
  a.next_toggle = !a.next_toggle;
  if (!end) return std::nullopt;
  a.active = false;
  const std::uint16_t crc = dronecan_transfer_crc(kRawImuSignature, a.payload.data(), a.size);
  if (crc != a.crc) return std::unexpected(transfer_error(f, "transfer CRC", crc));
  auto m = decode_raw_imu_payload(a.payload.data(), a.size);
  if (!m) return std::unexpected(transfer_error(f, "payload size", static_cast<std::int64_t>(a.size)));
  m->source_node = source;
  m->transfer_id = tid;
  return std::optional<DroneCanRawImu>(*m);
}

std::vector<CanFrame> encode_dronecan_raw_imu(const DroneCanRawImu& m, std::uint8_t source_node,
                                              std::uint8_t transfer_id, std::uint8_t priority) {
  std::vector<std::uint8_t> payload;
  put_le(payload, m.timestamp_us & ((std::uint64_t{1} << 56) - 1), 7);
  put_le(payload, std::bit_cast<std::uint32_t>(m.integration_interval_s), 4);
  for (float v : to_frd(m.gyro_radps)) put_le(payload, float_to_half(v), 2);
  for (float v : to_frd(m.gyro_integral)) put_le(payload, std::bit_cast<std::uint32_t>(v), 4);
  for (float v : to_frd(m.accel_mps2)) put_le(payload, float_to_half(v), 2);
  for (float v : to_frd(m.accel_integral)) put_le(payload, std::bit_cast<std::uint32_t>(v), 4);
  for (int i = 0; i < m.covariance_count && i < static_cast<int>(kRawImuMaxCovariance); ++i) put_le(payload, 0, 2);

  const std::uint32_t id = (static_cast<std::uint32_t>(priority & 0x1F) << 24) |
                           (std::uint32_t{kRawImuDataTypeId} << kDataTypeShift) | (source_node & 0x7Fu);
  std::vector<std::uint8_t> stream;  // what the frames carry before the tail bytes
  if (payload.size() > 7) {
    const std::uint16_t crc = dronecan_transfer_crc(kRawImuSignature, payload.data(), payload.size());
    stream = {static_cast<std::uint8_t>(crc), static_cast<std::uint8_t>(crc >> 8)};
  }
  stream.insert(stream.end(), payload.begin(), payload.end());
  std::vector<CanFrame> frames;
  bool toggle = false;
  for (std::size_t at = 0; at < stream.size(); at += 7) {
    const std::size_t n = std::min<std::size_t>(7, stream.size() - at);
    CanFrame f;
    f.id = id;
    f.flags = CanFlags::Extended;
    std::memcpy(f.data.data(), stream.data() + at, n);
    f.data[n] = static_cast<std::uint8_t>((at == 0 ? kTailStart : 0) | (at + n == stream.size() ? kTailEnd : 0) |
                                          (toggle ? kTailToggle : 0) | (transfer_id & kTailTransferId));
    f.len = static_cast<std::uint8_t>(n + 1);
    frames.push_back(f);
    toggle = !toggle;
  }
  return frames;
}

}  // namespace epichead::firmware_iface
