#pragma once
// The simulated IMU node on the camera mount: at every device tick it measures the true camera
// motion (true_imu) with the scenario's IMU errors and sends an ImuGyro + ImuAccel frame pair
// (same counter and wrapped device stamp). The errors come from imu_model's simulate_imu, drawn
// once for the whole run on a still mount: that run's measurement minus its scaled truth is the
// additive error (bias walk + white noise) of each tick, applied here to the closed-loop truth;
// scale factors, dropouts, device clock (offset, drift) and tick times are that run's too. So
// the closed loop has exactly the errors of `epichead sim` for the same seed, computed once and
// without allocation per sample.
#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "epichead/firmware_iface/can_frame.h"
#include "epichead/sim/imu_model.h"
#include "epichead/sim/trajectory.h"

namespace epichead::sim {

struct ImuNodeCounters {
  std::uint64_t samples = 0;       // device ticks measured
  std::uint64_t lost_model = 0;    // lost by the scenario's random dropouts (imu_dropouts)
  std::uint64_t lost_fault = 0;    // not sent during an imu_dropout fault
  std::uint64_t saturated = 0;     // samples with an axis at the sensor's range
  std::uint64_t encode_clipped = 0;  // samples beyond the wire's int16 range
};

// One measured sample and what goes on the bus.
struct ImuNodeSample {
  ImuSample sample;                // times, truth and measurement (camera axes)
  std::uint64_t device_us = 0;     // device clock
  std::uint8_t counter = 0;        // rolling, mod 16 on the wire
  bool send = false;               // false: lost (dropout): no frames
  std::array<firmware_iface::CanFrame, 2> frames;  // gyro, accel
};

class SimImuNode {
 public:
  // Ticks whose true time lies in [t0_s, t1_s].
  SimImuNode(const ImuParams& params, std::uint64_t seed, double t0_s, double t1_s);

  bool done() const { return next_ >= errors_.samples.size(); }
  double next_true_s() const { return errors_.samples[next_].t_true_s; }  // valid unless done()
  // Measures the next tick from the true camera motion at next_true_s(); `suppress` (a fault)
  // keeps it off the bus.
  const ImuNodeSample& measure_next(const Kinematics& world_T_imu, bool suppress);

  // The device clock at a true time (time-sync replies).
  std::uint64_t device_us(double t_true_s) const;
  firmware_iface::CanFrame heartbeat_frame(double t_s) const;
  const ImuNodeCounters& counters() const { return counters_; }
  const ImuRun& errors() const { return errors_; }

 private:
  ImuParams params_;
  ImuRun errors_;  // the still-mount run: per-tick errors, drawn scale factors, dropouts
  std::size_t next_ = 0;
  ImuNodeSample out_;
  ImuNodeCounters counters_;
};

}  // namespace epichead::sim
