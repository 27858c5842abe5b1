#pragma once
// The onboard loop's ports on a simulated world, as `epichead sim-run` sets them: the world's
// clock, bus and camera, and simulated time that advances as fast as the control thread asks.
#include "epichead/head/onboard_loop.h"
#include "epichead/sim/sim_world.h"

namespace epichead::testing {

inline head::OnboardPorts sim_onboard_ports(sim::SimWorld& w) {
  head::OnboardPorts ports;
  ports.clock = &w.clock();
  ports.bus = &w.bus();
  ports.camera = &w.camera();
  ports.simulated = true;  // the camera renders inside next_frame: not the tick's own work
  ports.wait_until = [&w](double t_s) { return w.advance_to(t_s); };
  return ports;
}

}  // namespace epichead::testing
