#pragma once
// The camera's orientation integrated from the camera-mounted gyro, in an "inertial" frame
// fixed at the first sample (it drifts with the gyro bias, a few mrad/s at most; the
// controllers only use it over short spans or close the loop through vision), and a fixed
// ring of past orientations so a target direction seen at a frame's exposure time can be
// carried to now (a new sample overwrites the oldest). Sized once; no allocation per sample.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/common/ring_buffer.h"

namespace epichead::head {

class GyroAttitude {
 public:
  // Keeps about history_s of samples at up to rate_hz.
  GyroAttitude(double history_s, double rate_hz);

  // Integrates a gyro sample (camera axes) taken at t_s over the interval since the previous
  // one (the rate of the newer sample is held over it; at 1 kHz the error is negligible).
  // A gap longer than max_gap_s restarts integration from the current orientation without
  // turning (the motion during the gap is unknown). Returns false for a sample not newer
  // than the previous one.
  bool add(double t_s, const Eigen::Vector3d& gyro_radps, double max_gap_s);

  bool empty() const { return ring_.empty(); }
  double newest_t_s() const;
  // inertial_R_cam at the newest sample.
  const Eigen::Quaterniond& newest() const { return newest_; }
  // inertial_R_cam at t_s, interpolated between stored samples; false when t_s is outside
  // the kept span (older than the oldest or newer than the newest by more than max_ahead_s;
  // a time slightly ahead holds the newest orientation).
  bool at(double t_s, Eigen::Quaterniond& out, double max_ahead_s = 0.005) const;
  void clear();

 private:
  struct Entry {
    double t_s = 0;
    Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  };
  common::RingBuffer<Entry> ring_;
  Eigen::Quaterniond newest_ = Eigen::Quaterniond::Identity();
};

}  // namespace epichead::head
