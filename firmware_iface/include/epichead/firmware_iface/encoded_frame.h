#pragma once
// What an encoder returns: the frame, and which signals had to be clipped to fit.
#include <cstdint>

#include "epichead/firmware_iface/can_frame.h"

namespace epichead::firmware_iface {

struct EncodedFrame {
  CanFrame frame;
  std::uint32_t clipped = 0;  // bit i = signal i of the message's signal table (signal_table.h)
};

}  // namespace epichead::firmware_iface
