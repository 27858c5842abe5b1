#pragma once
// Scaling SI values to the integer fields of the wire and back: round to nearest, clip to
// the field's range and say so, and flag raw values at the limits as saturated.
#include <cmath>
#include <cstdint>

namespace epichead::firmware_iface {

struct Quantized {
  std::int64_t raw = 0;
  bool clipped = false;  // the value was outside the field's range and was clipped to it
};

// value / per_lsb rounded to the nearest integer and clipped to [min_raw, max_raw]. The
// caller checks finiteness first (a NaN is an error, not a clipped value).
inline Quantized quantize(double value, double per_lsb, std::int64_t min_raw, std::int64_t max_raw) {
  const double scaled = std::nearbyint(value / per_lsb);
  if (scaled < static_cast<double>(min_raw)) return {min_raw, true};
  if (scaled > static_cast<double>(max_raw)) return {max_raw, true};
  return {static_cast<std::int64_t>(scaled), false};
}

// A signed field of `bits` bits: its limits.
constexpr std::int64_t signed_min(int bits) { return -(std::int64_t{1} << (bits - 1)); }
constexpr std::int64_t signed_max(int bits) { return (std::int64_t{1} << (bits - 1)) - 1; }
constexpr std::int64_t unsigned_max(int bits) { return (std::int64_t{1} << bits) - 1; }

}  // namespace epichead::firmware_iface
