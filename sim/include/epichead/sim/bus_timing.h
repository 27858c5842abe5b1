#pragma once
// Timing of the simulated CAN bus (scenario keys bus_latency_us, bus_jitter_us, bus_drop_rate,
// command_latency_us). Defaults are a 1 Mbit/s bus: an 8-byte frame takes about 110 us on the
// wire, plus the host's receive path.
namespace epichead::sim {

struct BusTiming {
  double latency_us = 200;          // node -> host: frame on the wire + host receive path
  double jitter_us = 100;           // extra node -> host delay, uniform in [0, jitter] per frame
  double drop_rate = 0;             // probability a node -> host frame is lost (seeded draw)
  double command_latency_us = 500;  // host -> node: until the node's firmware acts on a frame
};

}  // namespace epichead::sim
