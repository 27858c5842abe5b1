// The benchmarks' registry, filled by the static Registrations of the bench_*.cpp files.
#include "bench/bench.h"

namespace epichead::bench {
std::vector<Benchmark>& registry() {
  static std::vector<Benchmark> benchmarks;
  return benchmarks;
}
}  // namespace epichead::bench
