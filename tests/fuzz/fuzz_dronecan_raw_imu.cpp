// DroneCAN RawIMU reassembly (dronecan_raw_imu.h): a stream of frames from any nodes through
// one DroneCanRawImuDecoder. Properties: no crash, whatever the order, length, toggles, CRCs
// and times; every completed sample, encoded again by encode_dronecan_raw_imu, reassembles in
// a fresh decoder into the same sample (covariance values are not kept, only their count).
//
// Input: records of [time step: int16 ms, little-endian][flags][id: 4 bytes][length][data].
#include <cmath>
#include <cstring>
#include <string>

#include "epichead/firmware_iface/dronecan_raw_imu.h"
#include "fuzz_support.h"

using namespace epichead::firmware_iface;
using epichead::fuzz::check;

namespace {

bool same_value(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

template <std::size_t N>
bool same_values(const std::array<double, N>& a, const std::array<double, N>& b) {
  for (std::size_t i = 0; i < N; ++i)
    if (!same_value(a[i], b[i])) return false;
  return true;
}

bool same(const DroneCanRawImu& a, const DroneCanRawImu& b) {
  return a.source_node == b.source_node && a.transfer_id == b.transfer_id && a.timestamp_us == b.timestamp_us &&
         same_value(a.integration_interval_s, b.integration_interval_s) && same_values(a.gyro_radps, b.gyro_radps) &&
         same_values(a.accel_mps2, b.accel_mps2) && same_values(a.gyro_integral, b.gyro_integral) &&
         same_values(a.accel_integral, b.accel_integral) && a.covariance_count == b.covariance_count;
}

void check_round_trip(const DroneCanRawImu& m, std::int64_t stamp_us) {
  DroneCanRawImuDecoder fresh;
  std::optional<DroneCanRawImu> back;
  for (const CanFrame& f : encode_dronecan_raw_imu(m, m.source_node, m.transfer_id)) {
    check(!back.has_value(), "the re-encoded transfer completed before its last frame");
    auto r = fresh.push(StampedCanFrame{stamp_us, f});
    check(r.has_value(), "the re-encoded transfer is rejected: " + (r ? std::string() : r.error().message()));
    back = *r;
  }
  check(back.has_value(), "the re-encoded transfer does not complete");
  check(same(m, *back), "the re-encoded transfer decodes to another sample");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  epichead::fuzz::ByteReader in(data, size);
  DroneCanRawImuDecoder decoder;
  std::int64_t stamp_us = 0;
  while (!in.empty()) {
    const auto step_ms = static_cast<std::int16_t>(in.u8() | (in.u8() << 8));
    stamp_us += std::int64_t{step_ms} * 1000;
    StampedCanFrame s;
    s.stamp_us = stamp_us;
    CanFrame& f = s.frame;
    f.flags = static_cast<CanFlags>(in.u8() & 0x3F);
    f.id = in.u32() & 0x1FFFFFFFu;
    if (!f.extended()) f.id &= 0x7FFu;
    f.len = static_cast<std::uint8_t>(in.u8() % ((f.fd() ? kCanFdMaxData : kCanMaxData) + 1));
    for (std::size_t i = 0; i < f.len; ++i) f.data[i] = in.u8();
    const auto r = decoder.push(s);
    if (!r) {
      epichead::fuzz::check_one_line(r.error().message(), "wire error");
      continue;
    }
    if (*r) {
      check((*r)->covariance_count <= kRawImuMaxCovariance, "more covariance entries than the message has");
      check_round_trip(**r, stamp_us);
    }
  }
  return 0;
}
