#include "epichead/sim/sim_imu_node.h"

#include <cmath>
#include <limits>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/heartbeat.h"
#include "epichead/firmware_iface/imu_frames.h"
#include "node_heartbeat.h"
#include "saturate.h"

namespace epichead::sim {
namespace {

namespace fw = firmware_iface;

// The still-mount run that supplies the errors: no saturation (applied to the real values later).
ImuRun draw_errors(ImuParams p, std::uint64_t seed, double t0_s, double t1_s) {
  p.gyro_range_radps = p.accel_range_mps2 = std::numeric_limits<double>::infinity();
  return simulate_imu(p, seed, [](double) { return Kinematics{}; }, t0_s, t1_s);
}

}  // namespace

SimImuNode::SimImuNode(const ImuParams& params, std::uint64_t seed, double t0_s, double t1_s)
    : params_(params), errors_(draw_errors(params, seed, t0_s, t1_s)) {}

const ImuNodeSample& SimImuNode::measure_next(const Kinematics& world_T_imu, bool suppress) {
  const ImuSample& still = errors_.samples[next_++];
  ImuSample& s = out_.sample;
  s.t_true_s = still.t_true_s;
  s.t_device_s = still.t_device_s;
  true_imu(world_T_imu, s.gyro_true_radps, s.accel_true_mps2);
  // The still run measured scale * truth_still + error; its truth is zero rate and gravity.
  const Eigen::Vector3d gyro_error = still.gyro_radps - errors_.gyro_scale.cwiseProduct(still.gyro_true_radps);
  const Eigen::Vector3d accel_error = still.accel_mps2 - errors_.accel_scale.cwiseProduct(still.accel_true_mps2);
  s.gyro_radps = errors_.gyro_scale.cwiseProduct(s.gyro_true_radps) + gyro_error;
  s.accel_mps2 = errors_.accel_scale.cwiseProduct(s.accel_true_mps2) + accel_error;
  const bool clipped = saturate(s.gyro_radps, params_.gyro_range_radps) | saturate(s.accel_mps2, params_.accel_range_mps2);
  s.dropped = still.dropped;

  ++counters_.samples;
  counters_.saturated += clipped;
  out_.device_us = static_cast<std::uint64_t>(std::llround(s.t_device_s * 1e6));
  out_.counter = static_cast<std::uint8_t>((counters_.samples - 1) % fw::kImuCounterModulo);
  out_.send = !s.dropped && !suppress;
  if (s.dropped) ++counters_.lost_model;
  else if (suppress) ++counters_.lost_fault;
  if (!out_.send) return out_;

  fw::ImuGyro g;
  fw::ImuAccel a;
  g.counter = a.counter = out_.counter;
  g.stamp_mod_us = a.stamp_mod_us = fw::imu_stamp_mod_us(out_.device_us);
  for (int i = 0; i < 3; ++i) {
    g.value[i] = s.gyro_radps[i];
    a.value[i] = s.accel_mps2[i];
  }
  const auto eg = fw::encode(g);
  const auto ea = fw::encode(a);
  if (!eg || !ea) {  // only a non-finite value can fail: the truth is finite, so this is not expected
    out_.send = false;
    return out_;
  }
  counters_.encode_clipped += (eg->clipped | ea->clipped) != 0;
  out_.frames = {eg->frame, ea->frame};
  return out_;
}

std::uint64_t SimImuNode::device_us(double t_true_s) const {
  const double device_s = params_.clock_offset_s + (1.0 + params_.clock_drift) * t_true_s;
  return static_cast<std::uint64_t>(std::llround(std::max(0.0, device_s) * 1e6));
}

fw::CanFrame SimImuNode::heartbeat_frame(double t_s) const {
  return node_heartbeat_frame(fw::kNodeImu, fw::NodeState::Operational, t_s);
}

}  // namespace epichead::sim
