#include "epichead/sim/sim_can_bus.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "simulate_random.h"

namespace epichead::sim {
namespace {

constexpr std::uint64_t kBusStream = 51;

std::int64_t to_us(double t_s) { return std::llround(t_s * 1e6); }

// What SocketCAN would refuse to send: wrong length for the frame kind, id out of range.
const char* invalid_frame(const firmware_iface::CanFrame& f) {
  if (f.error()) return "error frames cannot be sent";
  if (f.fd() ? f.len > firmware_iface::kCanFdMaxData : f.len > firmware_iface::kCanMaxData) return "data length too long";
  if (f.id > (f.extended() ? 0x1FFFFFFFu : 0x7FFu)) return "identifier out of range";
  return nullptr;
}

}  // namespace

SimCanBus::SimCanBus(const BusTiming& timing, const FaultPlan& faults, std::uint64_t seed, const hw::Clock& clock,
                     std::function<void(double)> advance, std::size_t queue_capacity)
    : timing_(timing),
      faults_(faults),
      clock_(clock),
      advance_(std::move(advance)),
      seed_(seed),
      to_host_(queue_capacity),
      to_nodes_(queue_capacity) {}

std::expected<void, std::string> SimCanBus::send(const CanFrame& frame) {
  const double t = clock_.now_s();
  if (bus_off(t)) {
    ++stats_.tx_failed;
    return std::unexpected("sim CAN: send refused: bus-off (injected fault)");
  }
  if (const char* why = invalid_frame(frame)) {
    ++stats_.tx_failed;
    char buf[96];
    std::snprintf(buf, sizeof buf, "sim CAN: send refused for id 0x%X: %s", frame.id, why);
    return std::unexpected(std::string(buf));
  }
  if (!to_nodes_.try_push({t + timing_.command_latency_us * 1e-6, frame})) {
    ++stats_.tx_failed;
    return std::unexpected("sim CAN: send refused: transmit queue full");
  }
  ++stats_.tx_frames;
  return {};
}

hw::CanReceive SimCanBus::receive(StampedCanFrame& out, double timeout_s) {
  const double deadline =
      timeout_s < 0 ? std::numeric_limits<double>::infinity() : clock_.now_s() + timeout_s;
  for (;;) {
    const double t = clock_.now_s();
    if (bus_off(t)) {
      char buf[112];
      const FaultWindow* w = faults_.window_at(FaultKind::bus_off, t);
      std::snprintf(buf, sizeof buf, "sim CAN: bus-off (injected fault from %.6f s to %.6f s)", w->start_s,
                    w->start_s + w->duration_s);
      last_error_ = buf;
      return hw::CanReceive::Error;
    }
    if (!to_host_.empty() && to_host_.oldest().t_s <= t) {
      out.stamp_us = to_us(to_host_.oldest().t_s);
      out.frame = to_host_.oldest().frame;
      to_host_.pop_front();
      ++stats_.rx_frames;
      return hw::CanReceive::Frame;
    }
    if (!advance_ || t >= deadline) return hw::CanReceive::Timeout;
    // Waiting = letting the world run: in steps of at most 1 ms, since frames only appear
    // while it runs.
    advance_(std::min(deadline, t + 1e-3));
    if (clock_.now_s() <= t) return hw::CanReceive::Timeout;  // the world cannot move (its horizon)
  }
}

hw::CanBusStats SimCanBus::stats() const {
  hw::CanBusStats s = stats_;
  const double t = clock_.now_s();
  s.state = bus_off(t) ? hw::CanBusState::BusOff : hw::CanBusState::ErrorActive;
  s.bus_off_events = static_cast<std::uint64_t>(faults_.started(FaultKind::bus_off, t));
  return s;
}

void SimCanBus::node_send(const CanFrame& frame, double t_s) {
  ++counters_.node_frames;
  // Draws for every frame, lost or not, so a fault does not shift the later frames' timing.
  Random draw(seed_, kBusStream, draws_++);
  const double jitter_us = draw.uniform() * timing_.jitter_us;
  const bool drop = draw.uniform() < timing_.drop_rate;
  if (bus_off(t_s)) {
    ++counters_.lost_bus_off;
    return;
  }
  if (drop) {
    ++counters_.dropped_random;
    ++stats_.rx_dropped;
    return;
  }
  const double arrival = std::max(t_s + (timing_.latency_us + jitter_us) * 1e-6, last_arrival_s_);
  if (!to_host_.try_push({arrival, frame})) {
    ++counters_.rx_queue_overflow;
    ++stats_.rx_dropped;
    return;
  }
  last_arrival_s_ = arrival;
  counters_.max_delay_s = std::max(counters_.max_delay_s, arrival - t_s);
}

std::optional<double> SimCanBus::next_delivery_s() const {
  if (to_nodes_.empty()) return std::nullopt;
  return to_nodes_.oldest().t_s;
}

firmware_iface::CanFrame SimCanBus::pop_delivery() {
  const CanFrame f = to_nodes_.oldest().frame;
  to_nodes_.pop_front();
  return f;
}

std::optional<double> SimCanBus::next_arrival_s() const {
  if (to_host_.empty()) return std::nullopt;
  return to_host_.oldest().t_s;
}

}  // namespace epichead::sim
