// One 1 kHz head controller step (issue 9 item 1): Fixate with a gyro sample and a head state
// every tick and a tracker result every 33 ticks, as on the robot. Target: well under 10 us,
// no allocation.
#include <cmath>
#include <memory>
#include <stdexcept>

#include "bench/bench.h"
#include "epichead/head/head_controller.h"

namespace epichead::bench {
namespace {

struct HeadStep {
  explicit HeadStep(head::HeadController c) : controller(std::move(c)) {}
  head::HeadController controller;
  head::ControlInput in;
  head::ControlOutput out;
  long tick = 0;
};

const Registration head_step{"head_step", [] {
  auto c = head::HeadController::create({});
  if (!c) throw std::runtime_error(c.error());
  auto s = std::make_shared<HeadStep>(std::move(*c));
  s->controller.request(head::ControlMode::Fixate);
  s->in.gyro.emplace();
  s->in.head.emplace();
  return [s] {
    const long k = ++s->tick;
    const double t = static_cast<double>(k) * 1e-3;
    // Body-like motion: a few rad/s of wobble, the head moving, the target near the centre.
    s->in.t_s = t;
    s->in.gyro->t_s = t;
    s->in.gyro->gyro_radps = Eigen::Vector3d(0.3 * std::sin(7 * t), 0.2 * std::cos(5 * t), 0.1 * std::sin(3 * t));
    s->in.head->t_s = t;
    s->in.head->angles = {0.2 * std::sin(t), 0.1 * std::cos(t)};
    s->in.head->pan_rate_radps = 0.2 * std::cos(t);
    s->in.head->tilt_rate_radps = -0.1 * std::sin(t);
    if (k % 33 == 0) s->in.target = head::TargetObservation{t - 0.025, Eigen::Vector3d(0.05 * std::sin(t), 0.02, 3.0)};
    else s->in.target.reset();
    s->out = s->controller.step(s->in);
  };
}};

}  // namespace
}  // namespace epichead::bench
