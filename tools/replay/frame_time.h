#pragma once
// How long a frame occupies the bus, for the bus-load figure. Classic CAN frames are counted
// bit-exactly: the frame's fields from SOF to the CRC are built, the CRC-15 computed, the
// stuff bits that this exact bit pattern needs counted, and the fixed tail added (CRC
// delimiter, ACK slot and delimiter, 7 EOF bits, 3 intermission bits). CAN FD frames are
// estimated: arbitration phase bits at the nominal rate, data and CRC phase at the data rate
// when BRS is set, with the fixed stuff bits of the FD CRC and a 1-in-5 dynamic stuffing
// allowance. Error frames are counted as 20 bits (flag, up to 6 echo bits, delimiter, IFS).
#include <cstdint>

#include "epichead/firmware_iface/can_frame.h"

namespace epichead::tools::replay {

// Bits on the wire of a classic frame, stuff bits included (exact for this payload).
int classic_frame_bits(const firmware_iface::CanFrame& frame);

// Seconds the frame occupies the bus at the given nominal and data bit rates.
double frame_time_s(const firmware_iface::CanFrame& frame, double bitrate, double data_bitrate);

}  // namespace epichead::tools::replay
