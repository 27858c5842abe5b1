#include "epichead/head/joint_limits.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "epichead/firmware_iface/head_command.h"

namespace epichead::head {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kRateLsb = firmware_iface::kHeadRateRadpsPerLsb;

bool finite(double v) { return std::isfinite(v); }

}  // namespace

JointLimits default_pan_limits() { return {-170 * kDeg, 170 * kDeg, 6.0, 60.0}; }
JointLimits default_tilt_limits() { return {-60 * kDeg, 60 * kDeg, 6.0, 60.0}; }

std::expected<void, std::string> check(const JointLimits& l, const char* joint) {
  const std::string j = joint;
  if (!finite(l.min_rad) || !finite(l.max_rad) || !(l.min_rad < l.max_rad))
    return std::unexpected(j + " limits: min_rad must be below max_rad, both finite");
  if (!finite(l.rate_max_radps) || !(l.rate_max_radps >= kRateLsb))
    return std::unexpected(j + " limits: rate_max_radps must be finite and at least one wire LSB (0.005 rad/s)");
  if (!finite(l.accel_max_radps2) || !(l.accel_max_radps2 > 0))
    return std::unexpected(j + " limits: accel_max_radps2 must be finite and positive");
  return {};
}

double braking_rate_radps(double distance_rad, double accel_max_radps2, double dt_s) {
  if (distance_rad <= 0) return 0;
  // Commands at v, v - a dt, v - 2 a dt, ... each held for dt cover about
  // dt * (v + a dt / 2) + v^2 / (2 a). Solving v^2 / (2a) + 1.5 v dt = d for v keeps a margin.
  const double a = accel_max_radps2, h = 1.5 * dt_s;
  return a * (-h + std::sqrt(h * h + 2.0 * distance_rad / a));
}

JointCommand shape(const JointLimits& l, const JointCommand& previous, double desired_rate_radps, double dt_s,
                   std::uint8_t& hits) {
  hits = 0;
  const double dt = std::max(dt_s, 0.0);
  double v = finite(desired_rate_radps) ? desired_rate_radps : 0.0;
  if (std::abs(v) > l.rate_max_radps) {
    v = std::clamp(v, -l.rate_max_radps, l.rate_max_radps);
    hits |= kLimitRate;
  }
  // The braking curve toward each position limit, from where this step starts.
  const double up = braking_rate_radps(l.max_rad - previous.angle_rad, l.accel_max_radps2, dt);
  const double down = -braking_rate_radps(previous.angle_rad - l.min_rad, l.accel_max_radps2, dt);
  if (v > up) { v = up; hits |= kLimitBraking; }
  if (v < down) { v = down; hits |= kLimitBraking; }
  // The acceleration window wins over braking: it is what the motor can do, and the braking
  // curve was respected on the previous steps, so staying inside the window still stops in time.
  const double dv = l.accel_max_radps2 * dt;
  const double lo = previous.rate_radps - dv, hi = previous.rate_radps + dv;
  if (v < lo || v > hi) {
    v = std::clamp(v, lo, hi);
    hits |= kLimitAccel;
  }
  // Onto the wire's grid, inward: the quantised rate obeys the rate and acceleration limits.
  const double grid_hi = std::floor(std::min(hi, l.rate_max_radps) / kRateLsb + 1e-9) * kRateLsb;
  const double grid_lo = std::ceil(std::max(lo, -l.rate_max_radps) / kRateLsb - 1e-9) * kRateLsb;
  v = std::nearbyint(v / kRateLsb) * kRateLsb;
  if (grid_lo <= grid_hi) v = std::clamp(v, grid_lo, grid_hi);
  JointCommand next{previous.angle_rad + v * dt, v};
  if (next.angle_rad > l.max_rad || next.angle_rad < l.min_rad) {
    next.angle_rad = std::clamp(next.angle_rad, l.min_rad, l.max_rad);
    hits |= kLimitPosition;
  }
  return next;
}

}  // namespace epichead::head
