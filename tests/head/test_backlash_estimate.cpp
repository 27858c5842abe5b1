// The online backlash estimate (head/backlash_estimate.h): from the encoder's motor angle and
// the gyro's rate about the joint it finds the gear's play, ignores reversals inside a walking
// step's burst, never narrows a calibrated band, and closed around a head without play leaves the
// compensation off. (Closed around the simulator's head with untold play: tests/tools,
// test_sim_run_tool.cpp.)
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "epichead/head/backlash_estimate.h"
#include "epichead/head/head_controller.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using namespace epichead::head::testing;

namespace {

// One joint driven to and fro (a triangle of +-amplitude about 0, `period_s`), its output shaft
// behind a play of band_rad, the body turning at body_radps about the joint: 1 kHz gyro (noise
// gyro_noise_radps per sample), 200 Hz encoder on the 1e-4 rad grid of the wire.
struct SwingRun {
  double band_rad = 0.002;
  double amplitude_rad = 0.004;
  double period_s = 0.12;
  double body_radps = 0;
  double gyro_noise_radps = 0.005;
};

void swing(BacklashEstimator& e, const SwingRun& r, double seconds) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, r.gyro_noise_radps);
  const double dt = 1e-3;
  double output = 0, previous_output = 0;
  for (int i = 1; i <= static_cast<int>(seconds / dt); ++i) {
    const double t = i * dt;
    const double phase = std::fmod(t / r.period_s, 1.0);
    const double motor = r.amplitude_rad * (phase < 0.5 ? 4 * phase - 1 : 3 - 4 * phase);
    output = std::clamp(output, motor - 0.5 * r.band_rad, motor + 0.5 * r.band_rad);
    e.camera_rate((output - previous_output) / dt + r.body_radps + noise(rng), dt);
    previous_output = output;
    if (i % 5 == 0) e.motor_angle(t, std::nearbyint(motor / 1e-4) * 1e-4, r.body_radps);
  }
}

}  // namespace

TEST_CASE("the play of a joint swung to and fro is measured from encoder and gyro at its reversals",
          "[head][backlash]") {
  const double band = GENERATE(0.0005, 0.002, 0.006);
  BacklashEstimator e;
  SwingRun r;
  r.band_rad = band;
  swing(e, r, 3.0);
  INFO("band " << band << ": estimate " << e.estimate_rad() << " from " << e.samples() << " samples, " << e.rejected()
               << " rejected");
  REQUIRE(e.has_estimate());
  CHECK(e.samples() >= 20);
  CHECK(e.estimate_rad() == Approx(band).margin(1.5e-4));
  // The compensation gets a fraction of it, and never less than the calibration says.
  CHECK(e.band_rad(0) == Approx(0.85 * e.estimate_rad()));
  CHECK(e.band_rad(0.01) == 0.01);
}

TEST_CASE("a joint without play gives no band: the compensation stays off", "[head][backlash]") {
  BacklashEstimator e;
  SwingRun r;
  r.band_rad = 0;
  swing(e, r, 3.0);
  INFO("estimate " << e.estimate_rad() << " from " << e.samples() << " samples");
  CHECK(e.estimate_rad() < 1.5e-4);
  CHECK(e.band_rad(0) == 0);
}

TEST_CASE("reversals while the body turns fast are rejected and counted, not measured", "[head][backlash]") {
  BacklashEstimator e;
  SwingRun r;
  r.body_radps = 0.5;  // inside a walking step's burst
  swing(e, r, 3.0);
  CHECK(e.samples() == 0);
  CHECK(e.rejected() > 20);
  CHECK_FALSE(e.has_estimate());
  CHECK(e.band_rad(0.0005) == 0.0005);
}

namespace {

struct EstimatedRun {
  double target_rms_rad = 0;  // the target's angle from the optical axis, RMS after the first 2 s
  double jitter_rms_radps = 0;  // the camera's x/y rate less its 50 ms low-pass (the sway's smooth turn), RMS after 2 s
  JointBacklash band;
  std::uint64_t samples = 0;
};

// Fixating a target that sways to and fro (+-0.25 m sideways and +-0.15 m up and down at 4 m,
// every 2 s), the body still: both joints reverse every second. The head (the tests' plant: 2 ms
// motor lag, gyro noise and bias, tracker noise) has gear play plant_backlash_rad the controller
// is not told of.
EstimatedRun swaying_target_run(double plant_backlash_rad, bool estimate, std::uint64_t seed) {
  PlantOptions po;
  po.backlash_rad = plant_backlash_rad;
  po.gyro_noise_radps = 0.008;
  po.gyro_bias_radps = Eigen::Vector3d(0.002, -0.002, 0.001);
  po.seed = seed;
  HeadControllerOptions o;
  o.joint_rates.command_delay_s = po.command_latency_s + 0.001;
  o.joint_rates.motor_lag_s = po.motor_lag_s;
  o.backlash_estimate.enabled = estimate;
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  LoopOptions lo;
  lo.target_noise_rad = 0.0005;
  lo.target_sway_m = Eigen::Vector3d(0, 0.25, 0.15);
  ClosedLoop loop(std::move(*controller), HeadPlant(o.mount, po, {}, {0.0, 0.1}), lo);
  loop.tracker_on = true;
  loop.controller().request(ControlMode::Fixate);
  double sum = 0, sum_jitter = 0;
  int n = 0;
  Eigen::Vector2d smooth = Eigen::Vector2d::Zero();
  for (int i = 0; i < 10000; ++i) {
    loop.tick();
    const Eigen::Vector2d rate = loop.plant().true_camera_rate().head<2>();
    smooth += (1e-3 / 0.05) * (rate - smooth);
    if (loop.t_s() < 2.0) continue;
    sum += loop.target_angle_rad() * loop.target_angle_rad();
    sum_jitter += (rate - smooth).squaredNorm();
    ++n;
  }
  return {std::sqrt(sum / n), std::sqrt(sum_jitter / n), loop.controller().backlash_band(),
          loop.controller().counters().backlash_samples};
}

}  // namespace

TEST_CASE("in closed loop a head without play keeps the compensation off", "[head][backlash]") {
  const EstimatedRun run = swaying_target_run(0, true, 1);
  INFO("band pan " << run.band.pan_rad << " tilt " << run.band.tilt_rad << " from " << run.samples << " samples");
  CHECK(run.band.pan_rad == 0);
  CHECK(run.band.tilt_rad == 0);
}
