// The stabiliser on a walking-robot-like body: the camera's image-shifting rate drops at least
// tenfold against a fixed head (issue 9 target), with motor lag, command latency and gyro noise.
#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/head/head_controller.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using namespace epichead::head::testing;

namespace {

struct Rms {
  double xy = 0, all = 0;
};

// Runs `seconds` of walking with the controller in `mode` (or no commands at all: fixed head).
Rms run(bool stabilise, const PlantOptions& plant_options, double seconds, std::uint64_t seed, double lead_s = 0) {
  HeadControllerOptions o;
  o.rate_lead_s = lead_s;
  // The controller is told how its head responds (the head's data sheet or a step test).
  o.joint_rates.command_delay_s = plant_options.command_latency_s + 0.001;
  o.joint_rates.motor_lag_s = plant_options.motor_lag_s;
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  HeadPlant plant(o.mount, plant_options, walking_bursts(seconds, seed), {0.0, 0.1});
  ClosedLoop loop(std::move(*controller), std::move(plant));
  loop.controller().request(ControlMode::Stabilise);
  double sxy = 0, sall = 0;
  int n = 0;
  const int ticks = static_cast<int>(seconds * 1000);
  for (int i = 0; i < ticks; ++i) {
    if (stabilise) loop.tick();
    else loop.plant().advance_to((i + 1) * 1e-3);
    const Eigen::Vector3d w = loop.plant().true_camera_rate();
    sxy += w.head<2>().squaredNorm();
    sall += w.squaredNorm();
    ++n;
  }
  return {std::sqrt(sxy / n), std::sqrt(sall / n)};
}

}  // namespace

TEST_CASE("stabilisation cuts the camera's x/y angular-rate RMS at least tenfold against the fixed head",
          "[head][stabilise]") {
  PlantOptions plant;  // 2 ms motor lag, 0.5 ms command latency
  plant.gyro_noise_radps = 0.008;  // BMI088-class noise at 1 kHz
  plant.gyro_bias_radps = Eigen::Vector3d(0.002, -0.002, 0.001);
  for (std::uint64_t seed : {1u, 2u}) {
    const Rms fixed = run(false, plant, 8.0, seed);
    const Rms stab = run(true, plant, 8.0, seed);
    INFO("seed " << seed << ": fixed xy " << fixed.xy << " rad/s, stabilised xy " << stab.xy << " rad/s (all axes "
                 << fixed.all << " -> " << stab.all << ")");
    CHECK(fixed.xy > 0.05);
    CHECK(stab.xy * 10 <= fixed.xy);
    // Roll about the optical axis cannot be cancelled by pan and tilt: the total barely improves
    // where the bursts have roll (they do here), so the total is not a target.
    CHECK(stab.all < fixed.all);
  }
}

TEST_CASE("with a slow motor (10 ms lag) stabilisation helps less, and the body-rate lead makes up part of the delay",
          "[head][stabilise]") {
  PlantOptions plant;
  plant.motor_lag_s = 0.010;
  const Rms fixed = run(false, plant, 6.0, 3);
  const Rms stab = run(true, plant, 6.0, 3);
  const Rms lead = run(true, plant, 6.0, 3, 0.5 * (plant.motor_lag_s + plant.command_latency_s + 0.001));
  INFO("fixed xy " << fixed.xy << " stabilised xy " << stab.xy << " with lead " << lead.xy);
  CHECK(stab.xy * 3 < fixed.xy);
  CHECK(lead.xy < 0.95 * stab.xy);
}

TEST_CASE("stabilisation keeps the optical axis where it pointed at mode entry", "[head][stabilise]") {
  HeadControllerOptions o;
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  PlantOptions po;
  HeadPlant plant(o.mount, po, walking_bursts(6.0, 5), {0.2, 0.1});
  ClosedLoop loop(std::move(*controller), std::move(plant));
  loop.tick();
  const Eigen::Vector3d axis0 = loop.plant().world_R_cam() * Eigen::Vector3d::UnitZ();
  double worst = 0;
  for (int i = 0; i < 6000; ++i) {
    loop.tick();
    const Eigen::Vector3d axis = loop.plant().world_R_cam() * Eigen::Vector3d::UnitZ();
    worst = std::max(worst, std::acos(std::clamp(axis.dot(axis0), -1.0, 1.0)));
  }
  INFO("worst optical-axis excursion " << worst * 180 / 3.14159265 << " deg");
  CHECK(loop.outputs().back().mode == ControlMode::Stabilise);
  CHECK(worst < 0.5 * 3.14159265 / 180);  // under half a degree through 4 bursts of up to 80 deg/s
}
