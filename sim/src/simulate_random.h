#pragma once
// A small seeded random stream with fully specified output. The standard distributions'
// algorithms are implementation-defined, and the simulator promises byte-identical output
// for a seed, so uniform and normal draws are written out here.
#include <cmath>
#include <cstdint>

namespace epichead::sim {

class Random {
 public:
  // One independent stream per (seed, stream, index): the trajectory, the IMU noise, the start
  // pose and every frame each get their own, so changing one does not shift the others.
  explicit Random(std::uint64_t seed, std::uint64_t stream = 0, std::uint64_t index = 0)
      : state_(mix(mix(seed ^ 0x243f6a8885a308d3ULL) ^ mix(stream + 0x13198a2e03707344ULL) ^ mix(index))) {}

  std::uint64_t next_u64() {  // splitmix64
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    return mix_raw(z);
  }
  double uniform() { return static_cast<double>(next_u64() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  double normal() {  // Box-Muller, one value per call
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
  }

 private:
  static std::uint64_t mix_raw(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  static std::uint64_t mix(std::uint64_t z) { return mix_raw(z + 0x9e3779b97f4a7c15ULL); }
  std::uint64_t state_;
};

}  // namespace epichead::sim
