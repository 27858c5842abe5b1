#pragma once
// The project's benchmarks, run by `epichead bench`. A benchmark registers a factory that does
// its set-up (allocation allowed there) and returns the body of one iteration; the harness warms
// the body up, then times it and counts the heap allocations it makes (common/allocation_counter.h).
//
//   static const epichead::bench::Registration reg{"visibility_teabox", [] {
//     auto state = std::make_shared<...>(...);            // set-up
//     return [state] { state->vis.compute(pose, state->out); };  // one iteration
//   }};
//
// Keep results observable (write into state) so the optimiser cannot remove the work.
#include <functional>
#include <string>
#include <vector>

namespace epichead::bench {

using Iteration = std::function<void()>;
using Factory = std::function<Iteration()>;

struct Benchmark {
  std::string name;
  Factory make;
  // Work items per iteration (for example the pixels of a window), 0 if none: the harness then
  // also reports the median time per item, in ns.
  int items = 0;
};

std::vector<Benchmark>& registry();

struct Registration {
  Registration(std::string name, Factory make, int items = 0) {
    registry().push_back({std::move(name), std::move(make), items});
  }
};

}  // namespace epichead::bench
