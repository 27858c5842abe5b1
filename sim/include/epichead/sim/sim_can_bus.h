#pragma once
// The simulated CAN bus between the onboard program (host) and the simulated nodes (IMU, head).
// The host side is an hw::CanBus, so the onboard loop runs the same code as on SocketCAN.
//   node -> host: arrives latency + uniform(0, jitter) after it was sent, never before a frame
//                 sent earlier (CAN is one wire: frames keep their order); lost with
//                 probability drop_rate (seeded), counted in stats().rx_dropped.
//   host -> node: reaches the node's firmware command_latency after send().
//   bus-off (fault window): receive() returns Error with last_error() saying so,
//                 stats().state == BusOff, send() fails, frames the nodes send are lost. Frames
//                 that had already arrived stay queued and are read after the fault ends.
// No error frames are generated. Time comes from the world's clock; a receive() that may wait
// asks the world to advance (the only way the bus moves time). Single-threaded.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "epichead/common/ring_buffer.h"
#include "epichead/hw/can_bus.h"
#include "epichead/hw/clock.h"
#include "epichead/sim/bus_timing.h"
#include "epichead/sim/fault_plan.h"

namespace epichead::sim {

// Counts the hw::CanBusStats do not carry.
struct SimBusCounters {
  std::uint64_t node_frames = 0;        // frames the nodes put on the bus
  std::uint64_t dropped_random = 0;     // lost by the drop_rate draw
  std::uint64_t lost_bus_off = 0;       // node frames lost while bus-off
  std::uint64_t rx_queue_overflow = 0;  // the host did not read fast enough
  double max_delay_s = 0;               // largest node -> host delay seen
};

class SimCanBus final : public hw::CanBus {
 public:
  using CanFrame = firmware_iface::CanFrame;
  using StampedCanFrame = firmware_iface::StampedCanFrame;

  // `advance` moves the world's time forward (receive with a timeout); may be empty.
  SimCanBus(const BusTiming& timing, const FaultPlan& faults, std::uint64_t seed, const hw::Clock& clock,
            std::function<void(double t_s)> advance = {}, std::size_t queue_capacity = 8192);

  // hw::CanBus, the host side.
  std::expected<void, std::string> send(const CanFrame& frame) override;
  hw::CanReceive receive(StampedCanFrame& out, double timeout_s) override;
  hw::CanBusStats stats() const override;
  std::string_view last_error() const override { return last_error_; }

  // Node side, driven by the world in time order: a node sends a frame at t_s.
  void node_send(const CanFrame& frame, double t_s);
  // The earliest host -> node frame still in flight: when it reaches the nodes.
  std::optional<double> next_delivery_s() const;
  // Takes that frame.
  CanFrame pop_delivery();
  // When the next node -> host frame becomes readable (empty when none is queued).
  std::optional<double> next_arrival_s() const;

  bool bus_off(double t_s) const { return faults_.active(FaultKind::bus_off, t_s); }
  const SimBusCounters& counters() const { return counters_; }

 private:
  struct InFlight {
    double t_s = 0;  // arrival (node -> host) or delivery (host -> node)
    CanFrame frame;
  };
  BusTiming timing_;
  const FaultPlan& faults_;
  const hw::Clock& clock_;
  std::function<void(double)> advance_;
  std::uint64_t seed_, draws_ = 0;  // one Random(seed, stream, draws_++) per frame
  // Queues that refuse a frame when full (try_push): a full queue is a dropped frame, counted.
  common::RingBuffer<InFlight> to_host_, to_nodes_;
  double last_arrival_s_ = 0;
  hw::CanBusStats stats_;
  SimBusCounters counters_;
  std::string last_error_;
};

}  // namespace epichead::sim
