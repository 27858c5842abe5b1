// Closed-loop simulator benchmarks: one millisecond of the world (10 servo ticks, 1 IMU sample
// as 2 frames, head state/status frames) driven as the onboard loop drives it, without the
// camera's rendering (sim_render_box measures that). Must not allocate per step.
#include <cstdint>
#include <memory>
#include <stdexcept>

#include "bench/bench.h"
#include "epichead/firmware_iface/head_command.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sim_world.h"

namespace epichead::bench {
namespace {

struct WorldLoop {
  sim::Scenario scenario;
  sim::SimWorldOptions options;
  std::unique_ptr<sim::SimWorld> world;
  firmware_iface::HeadCommand command;
  std::uint64_t frames = 0;
};

std::unique_ptr<sim::SimWorld> make_world(const WorldLoop& s) {
  auto w = sim::SimWorld::create(s.scenario, s.options);
  if (!w) throw std::runtime_error(w.error());
  if (!(*w)->camera().start()) throw std::runtime_error("sim camera did not start");
  return std::move(*w);
}

const Registration world_1ms{"simworld_step_1ms", [] {
  auto s = std::make_shared<WorldLoop>();
  auto scenario = sim::find_scenario("mockup_walk");
  if (!scenario) throw std::runtime_error(scenario.error());
  s->scenario = *scenario;
  s->scenario.bus.drop_rate = 0.001;
  s->options.camera = sim::CameraOutput::Blank;
  s->options.camera_downscale = 8;
  // A long horizon (its IMU errors are drawn at creation): the timing loop rarely reaches it;
  // when it does, the world is made anew (an allocation burst seen in allocs/iter).
  s->options.horizon_s = 600;
  s->world = make_world(*s);
  const auto truth = s->world->truth_at(0);
  s->command.mode = firmware_iface::HeadMode::Position;
  s->command.pan_rad = truth->joints.pan_rad;
  s->command.tilt_rad = truth->joints.tilt_rad;
  return [s] {
    sim::SimWorld& w = *s->world;
    if (w.now_s() + 1e-3 > w.horizon_s()) s->world = make_world(*s);
    (void)s->world->advance_to(s->world->now_s() + 1e-3);
    firmware_iface::StampedCanFrame f;
    while (s->world->bus().receive(f, 0) == hw::CanReceive::Frame) ++s->frames;
    hw::CameraFrame image;
    while (s->world->camera().next_frame(image, 0) == hw::CameraRead::Frame) ++s->frames;
    s->command.counter = static_cast<std::uint8_t>((s->command.counter + 1) % 16);
    if (auto e = firmware_iface::encode(s->command)) (void)s->world->bus().send(e->frame);
  };
}};

}  // namespace
}  // namespace epichead::bench
