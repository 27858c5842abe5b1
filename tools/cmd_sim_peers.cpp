// `epichead sim-peers --can IFACE [--scenario NAME] [--seconds S] [--seed N]`: the simulator's
// IMU and pan/tilt head nodes on a real SocketCAN interface, in real time. The simulated world
// (body motion, IMU errors, head dynamics, time-sync answers; sim_world.h) is advanced to the
// elapsed CLOCK_MONOTONIC time every millisecond; what its nodes send goes out on IFACE and what
// arrives on IFACE (head commands, time-sync requests) is handed to them. So `epichead run` on
// the same interface talks to devices that behave like the robot's, e.g. over vcan in the VM
// test (tests/vm, docs/vm.md). The camera is not simulated here (run uses a V4L2 device).
// Says "running" once on the bus; runs for --seconds or until SIGINT/SIGTERM; prints one summary
// line either way and exits non-zero when the interface fails.
#include <CLI/CLI.hpp>

#include <time.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <memory>
#include <string>

#include "command.h"
#include "stop_signals.h"
#include "epichead/hw/clock.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/sim_world.h"

namespace epichead::tools {
namespace {

struct PeersArgs {
  std::string can, scenario = "mockup_walk";
  double seconds = 10;
  long long seed = -1;
};

std::atomic<bool> stop_requested{false};
extern "C" void on_peers_stop_signal(int) { stop_requested.store(true); }

// Sleeps until the monotonic clock reads t_s (absolute: a late wake-up does not shift the next).
void sleep_until(double t_s) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(t_s);
  ts.tv_nsec = static_cast<long>((t_s - static_cast<double>(ts.tv_sec)) * 1e9);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

int run_peers(const PeersArgs& a) {
  const char* cmd = "sim-peers";
  auto scenario = sim::find_scenario(a.scenario);
  if (!scenario) return fail(cmd, scenario.error());
  if (a.seed >= 0) scenario->seed = static_cast<std::uint64_t>(a.seed);
  sim::SimWorldOptions wo;
  wo.camera = sim::CameraOutput::Blank;  // no frames are taken from the simulated camera
  wo.horizon_s = a.seconds + 0.01;
  auto world = sim::SimWorld::create(*scenario, wo);
  if (!world) return fail(cmd, world.error());
  sim::SimWorld& w = **world;
  hw::SocketCanOptions can;
  can.interface = a.can;
  auto bus = hw::SocketCanBus::open(can);
  if (!bus) return fail(cmd, bus.error());

  on_stop_signals(on_peers_stop_signal);
  // Said once the nodes are on the bus, so a script can start the host side then.
  std::printf("sim-peers %s on %s: running\n", scenario->name.c_str(), a.can.c_str());
  std::fflush(stdout);
  const hw::Clock& clock = hw::monotonic_clock();
  const double start_s = clock.now_s();
  constexpr double kStep_s = 1e-3;
  constexpr double kLateStep_s = 0.01;  // a step this late means the nodes' frames left in a burst
  std::uint64_t to_bus = 0, from_bus = 0, send_failures = 0, bus_error_frames = 0, late_steps = 0;
  double max_lag_s = 0;
  firmware_iface::StampedCanFrame frame;
  for (std::uint64_t step = 1;; ++step) {
    const double due_s = start_s + static_cast<double>(step) * kStep_s;
    sleep_until(due_s);
    // Behind after a stall (a loaded machine): catch up in one go, the frames leave in a burst.
    const double woke_s = clock.now_s();
    const double lag_s = woke_s - due_s;
    max_lag_s = std::max(max_lag_s, lag_s);
    if (lag_s > kLateStep_s) ++late_steps;
    // After a stall the next wake-up is the next step after now: stepping through the missed
    // ones would spin without sleeping (the world is advanced to now in one go below).
    step = std::max(step, static_cast<std::uint64_t>((woke_s - start_s) / kStep_s));
    const double sim_t_s = std::min(woke_s - start_s, a.seconds);
    if (auto ok = w.advance_to(std::max(sim_t_s, w.now_s())); !ok) return fail(cmd, ok.error());
    // Nodes -> the real bus.
    while (w.bus().receive(frame, 0) == hw::CanReceive::Frame) {
      if ((*bus)->send(frame.frame)) {
        ++to_bus;
      } else {
        ++send_failures;  // counted: a full transmit queue loses the frame, as on the robot
      }
    }
    // The real bus -> the nodes (the host's head commands and time-sync requests).
    for (;;) {
      const hw::CanReceive got = (*bus)->receive(frame, 0);
      if (got == hw::CanReceive::Timeout) break;
      if (got == hw::CanReceive::Error) return fail(cmd, std::string((*bus)->last_error()));
      if (frame.frame.error()) {
        ++bus_error_frames;
        continue;
      }
      ++from_bus;
      (void)w.bus().send(frame.frame);  // the simulated bus counts what it refuses
    }
    if (sim_t_s >= a.seconds || stop_requested.load()) break;
  }
  const double ran_s = w.now_s();
  std::printf("sim-peers %s on %s: %.2f s, %llu frames sent (%llu failed), %llu received (%llu error frames), "
              "%llu IMU samples, %llu head commands, %llu time syncs answered; woke up to %.1f ms late, "
              "%llu steps over %.0f ms late\n",
              scenario->name.c_str(), a.can.c_str(), ran_s, static_cast<unsigned long long>(to_bus),
              static_cast<unsigned long long>(send_failures), static_cast<unsigned long long>(from_bus),
              static_cast<unsigned long long>(bus_error_frames),
              static_cast<unsigned long long>(w.imu_node().counters().samples),
              static_cast<unsigned long long>(w.head_node().counters().commands),
              static_cast<unsigned long long>(w.stats().time_syncs_answered), max_lag_s * 1e3,
              static_cast<unsigned long long>(late_steps), kLateStep_s * 1e3);
  return 0;
}

const CommandRegistration registration{
    "sim-peers", "The simulator's IMU and head nodes on a real SocketCAN interface, in real time", [](CLI::App& app) {
      auto a = std::make_shared<PeersArgs>();
      app.add_option("--can", a->can, "SocketCAN interface (e.g. vcan0)")->required();
      app.add_option("--scenario", a->scenario, "Built-in scenario name or .scn file (body motion, IMU, head)");
      app.add_option("--seconds", a->seconds, "How long to run (SIGINT or SIGTERM ends it sooner)")->check(CLI::Range(0.001, 86400.0));
      app.add_option("--seed", a->seed, "Override the scenario's seed");
      return [=]() { return run_peers(*a); };
    }};

}  // namespace
}  // namespace epichead::tools
