#pragma once
// An edge-detecting input port (the IMU's sync pulse): waits for the next edge and says when it
// happened, stamped by the kernel (Linux: CLOCK_MONOTONIC, given in ns and converted here to the
// program's seconds, docs/time.md) or by the simulator.
#include <cstdint>
#include <string_view>

namespace epichead::hw {

enum class GpioEdgeKind { Rising, Falling };

struct GpioEdge {
  double t_s = 0;  // CLOCK_MONOTONIC seconds, as hw::MonotonicClock
  GpioEdgeKind kind = GpioEdgeKind::Rising;
};

enum class GpioWait {
  Edge,     // `out` holds the next edge
  Timeout,  // none within the timeout
  Error,    // reading failed: see last_error()
};

class GpioEdgeInput {
 public:
  virtual ~GpioEdgeInput() = default;
  // Waits up to timeout_s (0: do not wait; negative: forever) for the next edge.
  virtual GpioWait wait_edge(GpioEdge& out, double timeout_s) = 0;
  virtual std::uint64_t edges() const = 0;  // edges delivered so far
  virtual std::string_view last_error() const = 0;
};

}  // namespace epichead::hw
