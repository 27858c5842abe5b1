// The onboard loop closed against the simulator (issue 9, item 6): every injected fault leads to
// the documented safe behaviour (docs/head.md, "Watchdog and safe behaviour") and to recovery; a
// run is deterministic for a seed; no command on the bus exceeds a joint limit. The loop is
// driven exactly as `epichead sim-run` drives it, with a blank camera (stabilise mode does not
// use vision), and judged by what it records: the candump log and the diagnostics stream.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/temp_dir.h"
#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/candump_reader.h"
#include "epichead/firmware_iface/head_command.h"
#include "epichead/head/joint_limits.h"
#include "epichead/head/onboard_loop.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/sim_world.h"
#include "sim_onboard_ports.h"

using namespace epichead;
namespace fw = epichead::firmware_iface;

namespace {

// mockup_walk's body motion and IMU, shortened; `extra` adds faults.
const std::string kBase =
    "scene mockup_walk\nframes 90\nmotion walking\nstart 0.30 -1.80 0.34\nheading_deg 98\nspeed_mps 0.03\n"
    "step_period_s 1.4\nfirst_step_s 0.3\nburst_degps 30 80\nburst_s 0.25\naim 0 0.05 0.36\n"
    "gyro_noise_radps_rthz 0.00025\ngyro_bias_radps 0.002\nimu_clock_offset_s 0.0137\nimu_clock_drift_ppm 40\n";

struct Command {
  double t_s = 0;
  fw::HeadCommand command;
};

struct Run {
  head::OnboardSummary summary;
  std::vector<nlohmann::json> events;  // controller events (mode changes, faults)
  std::vector<Command> commands;       // HeadCommand frames the loop sent
  std::string log_text, diagnostics_text;
};

Run run_loop(const std::string& extra, head::ControlMode mode, double seconds) {
  auto scenario = sim::parse_scenario(kBase + extra, "test.scn");
  INFO((scenario ? "" : scenario.error()));
  REQUIRE(scenario);
  sim::SimWorldOptions wo;
  wo.camera = sim::CameraOutput::Blank;
  wo.camera_downscale = 8;
  auto world = sim::SimWorld::create(*scenario, wo);
  REQUIRE(world);
  sim::SimWorld& w = **world;
  auto model = sim::make_scene_model(scenario->scene);
  REQUIRE(model);

  testing::TempDir dir("onboard_loop");
  head::OnboardOptions o;
  o.mode = mode;
  o.processing_s = 0.005;
  o.candump_path = dir / "bus.log";
  o.diagnostics_path = dir / "diagnostics.jsonl";
  const head::OnboardPorts ports = testing::sim_onboard_ports(w);
  auto loop = head::OnboardLoop::create(*model, w.camera_model(), o, ports);
  REQUIRE(loop);
  auto summary = (*loop)->run(seconds);
  INFO((summary ? "" : summary.error()));
  REQUIRE(summary);
  loop->reset();  // destroying the loop closes its diagnostics stream

  Run r;
  r.summary = *summary;
  std::ifstream diag(dir / "diagnostics.jsonl");
  std::stringstream ds;
  ds << diag.rdbuf();
  r.diagnostics_text = ds.str();
  std::istringstream lines(r.diagnostics_text);
  for (std::string line; std::getline(lines, line);) {
    auto j = nlohmann::json::parse(line);
    if (j.contains("event")) r.events.push_back(j);
  }
  std::ifstream log(dir / "bus.log");
  std::stringstream ls;
  ls << log.rdbuf();
  r.log_text = ls.str();
  auto reader = fw::CandumpReader::from_memory(r.log_text);
  fw::CandumpRecord rec;
  while (reader.next(rec)) {
    if (rec.frame.frame.id != fw::kIdHeadCommand || rec.direction != fw::CanDirection::Transmitted) continue;
    auto c = fw::decode_head_command(rec.frame.frame);
    REQUIRE(c);
    // The log is on the Unix epoch, simulated time 0 at the loop's fixed date (log_clock.h).
    r.commands.push_back({static_cast<double>(rec.frame.stamp_us - o.simulated_log_epoch_unix_us) * 1e-6, *c});
  }
  return r;
}

// The first event of a kind (and fault / target mode) at or after t_s, or null.
const nlohmann::json* find_event(const Run& r, const std::string& event, const std::string& what, double t_s) {
  for (const auto& e : r.events) {
    if (e["event"] != event || e["t_s"].get<double>() < t_s) continue;
    if (event == "mode_changed" ? e["to"] == what : e["fault"] == what) return &e;
  }
  return nullptr;
}

double commands_between(const Run& r, double t0, double t1) {
  double n = 0;
  for (const auto& c : r.commands) n += c.t_s >= t0 && c.t_s < t1;
  return n;
}

}  // namespace

TEST_CASE("onboard loop: an IMU dropout drops Stabilise to Hold, when samples return it stabilises again",
          "[tools][onboard][fault]") {
  const Run r = run_loop("fault imu_dropout 1.0 0.3\n", head::ControlMode::Stabilise, 2.0);
  INFO(r.diagnostics_text.substr(0, 3000));
  const auto* raised = find_event(r, "fault_raised", "imu_stale", 0.5);
  REQUIRE(raised);
  CHECK((*raised)["t_s"].get<double>() == Approx(1.01).margin(0.01));  // 10 ms without a gyro sample
  const auto* hold = find_event(r, "mode_changed", "hold", 0.5);
  REQUIRE(hold);
  CHECK((*hold)["reason"] == "imu_stale");
  const auto* cleared = find_event(r, "fault_cleared", "imu_stale", 1.3);
  REQUIRE(cleared);
  CHECK((*cleared)["t_s"].get<double>() < 1.45);  // samples fresh for 50 ms after the dropout
  const auto* back = find_event(r, "mode_changed", "stabilise", 1.3);
  REQUIRE(back);
  CHECK((*back)["reason"] == "recovered");
  CHECK(r.summary.predictor.dropouts >= 1);
  // Commands keep going out through the dropout (Hold is a commanded state).
  CHECK(commands_between(r, 1.05, 1.25) > 150);
}

TEST_CASE("onboard loop: bus-off withholds commands and holds, after the bus recovers commands resume from the measured state",
          "[tools][onboard][fault]") {
  const Run r = run_loop("fault bus_off 1.0 0.3\n", head::ControlMode::Stabilise, 2.0);
  INFO(r.diagnostics_text.substr(0, 3000));
  const auto* raised = find_event(r, "fault_raised", "bus_off", 0.5);
  REQUIRE(raised);
  const auto* hold = find_event(r, "mode_changed", "hold", 0.5);
  REQUIRE(hold);
  CHECK((*hold)["reason"] == "bus_off");
  // Nothing is put on the bus while it is off (a few ms after the fault's start: detection).
  CHECK(commands_between(r, 1.01, 1.3) == 0);
  CHECK(r.summary.commands_withheld > 250);
  const auto* cleared = find_event(r, "fault_cleared", "bus_off", 1.3);
  REQUIRE(cleared);
  REQUIRE(find_event(r, "mode_changed", "stabilise", 1.3));
  CHECK(commands_between(r, 1.5, 2.0) > 450);
}

TEST_CASE("onboard loop: a stuck joint does not wind up the command, the joint follows again when freed",
          "[tools][onboard][fault]") {
  const Run r = run_loop("fault stuck_joint tilt 0.2 0.6\n", head::ControlMode::Stabilise, 1.6);
  // The commanded tilt never runs further than max_following_error_rad (0.2 rad) from where the
  // joint is, so it cannot lunge when it frees.
  CHECK(r.summary.controller.following_error_clamped > 0);
  double worst_step = 0;
  for (std::size_t i = 1; i < r.commands.size(); ++i)
    worst_step = std::max(worst_step, std::abs(r.commands[i].command.tilt_rad - r.commands[i - 1].command.tilt_rad));
  CHECK(worst_step < 0.01);  // no jump in the commanded angle, freed or not
  CHECK(r.summary.controller.steps > 1500);
}

TEST_CASE("onboard loop: no command on the bus exceeds a joint's position, rate or acceleration limit",
          "[tools][onboard][limits]") {
  // Jerkier than the default walk, so the limits are reached.
  const Run r = run_loop("jerk 3\n", head::ControlMode::Stabilise, 3.0);
  const head::JointLimits pan = head::default_pan_limits(), tilt = head::default_tilt_limits();
  REQUIRE(r.commands.size() > 2500);
  const double rate_lsb = 0.005, tick_s = 0.001;
  for (std::size_t i = 0; i < r.commands.size(); ++i) {
    const fw::HeadCommand& c = r.commands[i].command;
    INFO("command " << i << " at " << r.commands[i].t_s << " s");
    CHECK(c.pan_rad >= pan.min_rad);
    CHECK(c.pan_rad <= pan.max_rad);
    CHECK(c.tilt_rad >= tilt.min_rad);
    CHECK(c.tilt_rad <= tilt.max_rad);
    CHECK(std::abs(c.pan_rate_radps) <= pan.rate_max_radps + rate_lsb / 2);
    CHECK(std::abs(c.tilt_rate_radps) <= tilt.rate_max_radps + rate_lsb / 2);
    if (i == 0) continue;
    const fw::HeadCommand& p = r.commands[i - 1].command;
    // One tick apart: the rate changes by at most accel_max * tick, plus the wire's rounding.
    CHECK(std::abs(c.pan_rate_radps - p.pan_rate_radps) <= pan.accel_max_radps2 * tick_s + rate_lsb + 1e-9);
    CHECK(std::abs(c.tilt_rate_radps - p.tilt_rate_radps) <= tilt.accel_max_radps2 * tick_s + rate_lsb + 1e-9);
  }
}

TEST_CASE("onboard loop: a closed-loop run is deterministic for a seed (bus log and diagnostics identical)",
          "[tools][onboard]") {
  const Run a = run_loop("seed 7\n", head::ControlMode::Stabilise, 1.0);
  const Run b = run_loop("seed 7\n", head::ControlMode::Stabilise, 1.0);
  const Run c = run_loop("seed 8\n", head::ControlMode::Stabilise, 1.0);
  REQUIRE(a.log_text.size() > 10000);
  CHECK(a.log_text == b.log_text);
  CHECK(a.diagnostics_text == b.diagnostics_text);
  CHECK(a.log_text != c.log_text);  // the seed does reach the run
}

TEST_CASE("onboard loop: a camera stall stops the frames for its length, not the control loop", "[tools][onboard][fault]") {
  const Run normal = run_loop("", head::ControlMode::Stabilise, 2.0);
  const Run stalled = run_loop("fault camera_stall 0.5 1.0\n", head::ControlMode::Stabilise, 2.0);
  INFO("frames " << normal.summary.frames << " normally, " << stalled.summary.frames << " with a 1 s stall");
  CHECK(normal.summary.frames >= 50);
  CHECK(stalled.summary.frames <= normal.summary.frames - 25);  // 30 frames/s stopped for 1 s
  CHECK(stalled.summary.frames >= 20);                          // and they come back after it
  CHECK(commands_between(stalled, 0.6, 1.4) >= 790);            // the 1 kHz loop went on
}
