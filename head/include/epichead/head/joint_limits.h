#pragma once
// Joint position, rate and acceleration limits and the shaper that makes every command obey
// them. The shaper turns a desired joint rate into the next command (angle, rate) such that
//   min_rad <= angle <= max_rad, |rate| <= rate_max, |rate - previous rate| <= accel_max * dt,
// and the joint can always brake to rest before a position limit (a braking curve, not a
// clamp that would ask for infinite deceleration). Rates are kept on the wire's rate grid
// (firmware_iface::kHeadRateRadpsPerLsb) so the quantised command obeys the limits too.
#include <cstdint>
#include <expected>
#include <string>

namespace epichead::head {

struct JointLimits {
  double min_rad = 0, max_rad = 0;
  double rate_max_radps = 6.0;
  double accel_max_radps2 = 60.0;
};

// The defaults: pan +-170 deg, tilt -60..+60 deg, 6 rad/s, 60 rad/s^2.
JointLimits default_pan_limits();
JointLimits default_tilt_limits();

// Finite, min < max, positive rate and acceleration; the error names the joint and field.
std::expected<void, std::string> check(const JointLimits& limits, const char* joint);

// Which limit shaped a command this tick (bits).
enum LimitHit : std::uint8_t {
  kLimitRate = 1u << 0,      // desired rate beyond rate_max
  kLimitAccel = 1u << 1,     // desired rate change beyond accel_max * dt
  kLimitBraking = 1u << 2,   // slowed down to stop before a position limit
  kLimitPosition = 1u << 3,  // angle clamped at a position limit (safety net)
};

// One joint's commanded motion.
struct JointCommand {
  double angle_rad = 0;
  double rate_radps = 0;
};

// Largest speed from which the joint, decelerating at accel_max, stops within distance_rad
// when commands come every dt_s (the discrete braking curve).
double braking_rate_radps(double distance_rad, double accel_max_radps2, double dt_s);

// The next command from the previous one and a desired rate over dt_s. `hits` gets LimitHit bits.
JointCommand shape(const JointLimits& limits, const JointCommand& previous, double desired_rate_radps, double dt_s,
                   std::uint8_t& hits);

}  // namespace epichead::head
