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

GyroAttitude::GyroAttitude(double history_s, double rate_hz) {
  const double n = std::clamp(history_s * rate_hz, 2.0, 1e6);
  ring_.resize(static_cast<std::size_t>(std::ceil(n)) + 2);
}

void GyroAttitude::clear() {
  head_ = count_ = 0;
  newest_ = Eigen::Quaterniond::Identity();
}

double GyroAttitude::newest_t_s() const { return count_ == 0 ? 0.0 : entry(count_ - 1).t_s; }

const GyroAttitude::Entry& GyroAttitude::entry(std::size_t i) const {
  return ring_[(head_ + ring_.size() - count_ + i) % ring_.size()];
}

bool GyroAttitude::add(double t_s, const Eigen::Vector3d& gyro_radps, double max_gap_s) {
  if (count_ > 0) {
    const double dt = t_s - newest_t_s();
    if (!(dt > 0)) return false;
    if (dt <= max_gap_s) {
      newest_ = (newest_ * quat_exp(gyro_radps * dt)).normalized();
    }
  }
  ring_[head_] = {t_s, newest_};
  head_ = (head_ + 1) % ring_.size();
  count_ = std::min(count_ + 1, ring_.size());
  return true;
}

bool GyroAttitude::at(double t_s, Eigen::Quaterniond& out, double max_ahead_s) const {
  if (count_ == 0) return false;
  const Entry& newest = entry(count_ - 1);
  if (t_s >= newest.t_s) {
    if (t_s - newest.t_s > max_ahead_s) return false;
    out = newest.q;
    return true;
  }
  if (t_s < entry(0).t_s) return false;
  // Binary search for the first entry newer than t_s.
  std::size_t lo = 0, hi = count_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (entry(mid).t_s > t_s) hi = mid; else lo = mid + 1;
  }
  const Entry& b = entry(lo);
  const Entry& a = entry(lo - 1);
  const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
  out = a.q.slerp(f, b.q);
  return true;
}

}  // namespace epichead::head
