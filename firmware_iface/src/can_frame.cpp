#include "epichead/firmware_iface/can_frame.h"

namespace epichead::firmware_iface {

const char* impossible_frame_reason(const CanFrame& f) {
  if (f.error()) {
    // Linux reports controller errors as classic frames: CAN_ERR_FLAG | class, 8 bytes.
    if (f.remote()) return "an error frame cannot be a remote frame";
    if (f.fd()) return "an error frame cannot be a CAN FD frame";
    if (f.extended()) return "an error frame has no 11/29-bit id format (its id is the error class)";
    if (f.id > 0x1FFFFFFFu) return "error class wider than 29 bits";
    if (f.len > kCanMaxData) return "an error frame has at most 8 data bytes";
    return nullptr;
  }
  if (f.extended() ? f.id > 0x1FFFFFFFu : f.id > 0x7FFu)
    return f.extended() ? "29-bit CAN id wider than 29 bits" : "11-bit CAN id wider than 11 bits";
  if (f.fd()) {
    if (f.remote()) return "CAN FD has no remote frames";
    const int n = f.len;
    if (!(n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64))
      return "CAN FD data length is not one of 0..8, 12, 16, 20, 24, 32, 48, 64";
    return nullptr;
  }
  if (has(f.flags, CanFlags::BitRateSwitch) || has(f.flags, CanFlags::ErrorStateIndicator))
    return "bit rate switch and error state indicator exist only on CAN FD frames";
  if (f.len > kCanMaxData) return "a classic CAN frame has at most 8 data bytes";
  return nullptr;
}

}  // namespace epichead::firmware_iface
