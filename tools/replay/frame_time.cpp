#include "replay/frame_time.h"

#include <array>

namespace epichead::tools::replay {

using firmware_iface::CanFlags;
using firmware_iface::CanFrame;

namespace {

// The frame's bits from SOF to the end of the CRC, in bus order (dominant 0, recessive 1).
struct BitBuffer {
  std::array<std::uint8_t, 160> bits{};
  int n = 0;
  void put(std::uint32_t value, int count) {
    for (int i = count - 1; i >= 0; --i) bits[static_cast<std::size_t>(n++)] = (value >> i) & 1u;
  }
};

std::uint32_t crc15(const BitBuffer& b) {
  std::uint32_t crc = 0;
  for (int i = 0; i < b.n; ++i) {
    const std::uint32_t next = b.bits[static_cast<std::size_t>(i)] ^ ((crc >> 14) & 1u);
    crc = (crc << 1) & 0x7FFF;
    if (next) crc ^= 0x4599;
  }
  return crc;
}

int stuff_bits(const BitBuffer& b) {
  int stuffed = 0, run = 0;
  int last = -1;
  for (int i = 0; i < b.n; ++i) {
    const int bit = b.bits[static_cast<std::size_t>(i)];
    if (bit == last) {
      ++run;
    } else {
      last = bit;
      run = 1;
    }
    if (run == 5) {  // a stuff bit of the opposite level follows and starts a new run
      ++stuffed;
      last = !bit;
      run = 1;
    }
  }
  return stuffed;
}

}  // namespace

int classic_frame_bits(const CanFrame& f) {
  BitBuffer b;
  const int len = f.len > 8 ? 8 : f.len;
  const std::uint32_t rtr = f.remote() ? 1 : 0;
  b.put(0, 1);  // SOF
  if (f.extended()) {
    b.put(f.id >> 18, 11);  // base id
    b.put(1, 1);            // SRR
    b.put(1, 1);            // IDE
    b.put(f.id & 0x3FFFF, 18);
    b.put(rtr, 1);
    b.put(0, 2);  // r1, r0
  } else {
    b.put(f.id & 0x7FF, 11);
    b.put(rtr, 1);
    b.put(0, 1);  // IDE
    b.put(0, 1);  // r0
  }
  b.put(static_cast<std::uint32_t>(len), 4);
  if (!f.remote())
    for (int i = 0; i < len; ++i) b.put(f.data[static_cast<std::size_t>(i)], 8);
  b.put(crc15(b), 15);
  constexpr int kTail = 1 + 2 + 7 + 3;  // CRC delimiter, ACK slot + delimiter, EOF, IFS
  return b.n + stuff_bits(b) + kTail;
}

double frame_time_s(const CanFrame& f, double bitrate, double data_bitrate) {
  if (f.error()) return 20.0 / bitrate;
  if (!f.fd()) return classic_frame_bits(f) / bitrate;
  // CAN FD estimate. Arbitration phase: SOF, id, (SRR, IDE, id ext), RRS, IDE, FDF, res, BRS,
  // then ESI, DLC, data, stuff count, CRC, CRC delimiter at the data rate with BRS.
  const int arb = f.extended() ? 1 + 11 + 1 + 1 + 18 + 1 + 1 + 1 + 1 : 1 + 11 + 1 + 1 + 1 + 1 + 1;
  const int crc_bits = f.len > 16 ? 21 : 17;
  const double data_bits = 1 + 4 + 8.0 * f.len + 4 + crc_bits + crc_bits / 4.0 /* fixed stuff */;
  const double stuffed_arb = arb * 1.2, stuffed_data = 1 + 4 + 8.0 * f.len;  // dynamic stuffing
  const double data_rate = has(f.flags, CanFlags::BitRateSwitch) ? data_bitrate : bitrate;
  const double tail = 1 + 2 + 7 + 3;
  return (stuffed_arb + tail) / bitrate + (data_bits + stuffed_data * 0.2) / data_rate;
}

}  // namespace epichead::tools::replay
