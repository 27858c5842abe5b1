#include "epichead/head/gyro_attitude.h"

#include <algorithm>
#include <cmath>

namespace epichead::head {
namespace {

// exp of a rotation vector as a quaternion (exact; Eigen's AngleAxis needs the norm anyway).
Eigen::Quaterniond quat_exp(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  if (a < 1e-12) return Eigen::Quaterniond(1, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z()).normalized();
  return Eigen::Quaterniond(Eigen::AngleAxisd(a, phi / a));
}

}  // namespace

GyroAttitude::GyroAttitude(double history_s, double rate_hz)
    : ring_(static_cast<std::size_t>(std::ceil(std::clamp(history_s * rate_hz, 2.0, 1e6))) + 2) {}

void GyroAttitude::clear() {
  ring_.clear();
  newest_ = Eigen::Quaterniond::Identity();
}

double GyroAttitude::newest_t_s() const { return ring_.empty() ? 0.0 : ring_.newest().t_s; }

bool GyroAttitude::add(double t_s, const Eigen::Vector3d& gyro_radps, double max_gap_s) {
  if (!ring_.empty()) {
    const double dt = t_s - newest_t_s();
    if (!(dt > 0)) return false;
    if (dt <= max_gap_s) {
      newest_ = (newest_ * quat_exp(gyro_radps * dt)).normalized();
    }
  }
  ring_.push_overwrite({t_s, newest_});
  return true;
}

bool GyroAttitude::at(double t_s, Eigen::Quaterniond& out, double max_ahead_s) const {
  if (ring_.empty()) return false;
  const Entry& newest = ring_.newest();
  if (t_s >= newest.t_s) {
    if (t_s - newest.t_s > max_ahead_s) return false;
    out = newest.q;
    return true;
  }
  if (t_s < ring_.oldest().t_s) return false;
  // Binary search for the first entry newer than t_s.
  std::size_t lo = 0, hi = ring_.size() - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (ring_[mid].t_s > t_s) hi = mid; else lo = mid + 1;
  }
  const Entry& b = ring_[lo];
  const Entry& a = ring_[lo - 1];
  const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
  out = a.q.slerp(f, b.q);
  return true;
}

}  // namespace epichead::head
