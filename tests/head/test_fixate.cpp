// Fixation: the target's image position is brought to the centre and kept there while the
// body jerks, using the tracker's latency-stamped observations; the delay from exposure to the
// command that uses it is the processing time, nothing more.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "epichead/head/head_controller.h"
#include "head_sim_helpers.h"

using namespace epichead::head;
using namespace epichead::head::testing;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

ClosedLoop make_loop(const LoopOptions& loop_options, double seconds, std::uint64_t burst_seed, bool bursts = true,
                     HeadControllerOptions o = {}) {
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  PlantOptions po;
  po.gyro_noise_radps = 0.008;
  po.gyro_bias_radps = Eigen::Vector3d(0.003, -0.002, 0.002);
  HeadPlant plant(o.mount, po, bursts ? walking_bursts(seconds, burst_seed) : std::vector<BodyBurst>{}, {0.0, 0.0});
  ClosedLoop loop(std::move(*controller), std::move(plant), loop_options);
  loop.controller().request(ControlMode::Fixate);
  loop.tracker_on = true;
  return loop;
}

// RMS of the target's angle from the optical axis over [from_s, to_s].
double rms_angle(ClosedLoop& loop, double from_s, double to_s) {
  double s = 0;
  int n = 0;
  while (loop.t_s() < to_s - 1e-9) {
    loop.tick();
    if (loop.t_s() >= from_s) {
      s += loop.target_angle_rad() * loop.target_angle_rad();
      ++n;
    }
  }
  return std::sqrt(s / std::max(n, 1));
}

}  // namespace

TEST_CASE("fixation brings a target more than 10 degrees off to the image centre and keeps it there", "[head][fixate]") {
  LoopOptions lo;
  lo.target_world = {4.0, 0.6, -0.35};  // left and below the start pointing
  ClosedLoop loop = make_loop(lo, 6, 1, false);
  const double start = loop.target_angle_rad();
  CHECK(start > 8 * kDeg);
  const double settled = rms_angle(loop, 1.5, 3.0);
  INFO("start " << start / kDeg << " deg, settled RMS " << settled / kDeg << " deg");
  CHECK(settled < 0.1 * kDeg);
  CHECK(loop.outputs().back().mode == ControlMode::Fixate);
  // The controller's own estimate of the error agrees with the truth.
  CHECK(std::abs(loop.outputs().back().target_error_rad - loop.target_angle_rad()) < 0.1 * kDeg);
}

TEST_CASE("fixation keeps the target centred through walking bursts (under 3 px RMS at 530 px focal length)",
          "[head][fixate]") {
  LoopOptions lo;
  lo.target_noise_rad = 0.5e-3;  // tracker noise, about a quarter pixel
  ClosedLoop loop = make_loop(lo, 10, 4);
  const double rms = rms_angle(loop, 1.0, 10.0);
  const double px = 530 * std::tan(rms);
  INFO("RMS " << rms / kDeg << " deg = " << px << " px");
  CHECK(px < 3);
}

TEST_CASE("fixation follows a moving target with the estimated target rate", "[head][fixate]") {
  LoopOptions lo;
  lo.target_world = {3.0, -0.3, 0.0};
  lo.target_velocity_mps = {0.0, 0.4, 0.0};  // about 7.6 deg/s across the view
  ClosedLoop loop = make_loop(lo, 4, 1, false);
  const double rms = rms_angle(loop, 1.5, 3.0);
  INFO("RMS " << rms / kDeg << " deg");
  CHECK(rms < 0.3 * kDeg);
}

TEST_CASE("fixation uses the exposure time: stamping results at their arrival instead is worse", "[head][fixate]") {
  // The camera turns while a frame is processed (a slew toward a target 14 deg off, then a
  // moving target) and processing takes 100 ms: only the exposure-time attitude places the
  // observation right; stamped at arrival the loop sees stale errors as current and swings.
  LoopOptions good;
  good.target_world = {4.0, 0.6, -0.35};
  good.target_velocity_mps = {0.0, -0.5, 0.0};
  good.processing_s = 0.1;
  LoopOptions wrong = good;
  wrong.stamp_at_arrival = true;
  ClosedLoop a = make_loop(good, 3, 6, false);
  ClosedLoop b = make_loop(wrong, 3, 6, false);
  const double rms_good = rms_angle(a, 1.0, 3.0);
  const double rms_wrong = rms_angle(b, 1.0, 3.0);
  INFO("exposure-stamped " << rms_good / kDeg << " deg, arrival-stamped " << rms_wrong / kDeg << " deg");
  CHECK(rms_good < 0.1 * kDeg);
  CHECK(rms_good * 5 < rms_wrong);
}

TEST_CASE("a target observation changes the command in the tick it arrives (no added delay)", "[head][fixate]") {
  HeadControllerOptions o;
  auto make = [&] {
    auto c = HeadController::create(o);
    REQUIRE(c);
    c->request(ControlMode::Fixate);
    return std::move(*c);
  };
  HeadController a = make(), b = make();
  ControlInput in;
  in.head = JointState{0, {0.1, 0.05}, 0, 0};
  for (int i = 1; i <= 300; ++i) {
    in.t_s = i * 1e-3;
    in.gyro = GyroReading{in.t_s, Eigen::Vector3d::Zero()};
    in.head->t_s = in.t_s;
    in.target = TargetObservation{in.t_s - 0.02, Eigen::Vector3d(0.0, 0.0, 3.0)};
    ControlInput in_b = in;
    if (i == 300) in_b.target = TargetObservation{in.t_s - 0.02, Eigen::Vector3d(0.3, 0.0, 3.0)};
    const ControlOutput oa = a.step(in), ob = b.step(in_b);
    if (i < 300) REQUIRE(oa.command.pan_rate_radps == ob.command.pan_rate_radps);
    else CHECK(oa.command.pan_rate_radps != ob.command.pan_rate_radps);
  }
}

TEST_CASE("fixation turns the camera no faster than fixate_max_rate_radps toward a far-off target", "[head][fixate]") {
  HeadControllerOptions o;
  o.fixate_max_rate_radps = 0.5;
  LoopOptions lo;
  lo.target_world = {2.0, 2.0, 0.0};  // 45 deg to the left
  ClosedLoop loop = make_loop(lo, 4, 1, false, o);
  double peak = 0;
  for (int i = 0; i < 3000; ++i) {
    loop.tick();
    peak = std::max(peak, loop.plant().true_camera_rate().head<2>().norm());
  }
  INFO("peak camera rate " << peak << " rad/s");
  CHECK(peak < 0.5 * 1.15);  // target-rate feed-forward and motor overshoot add a little
  CHECK(loop.target_angle_rad() < 0.2 * kDeg);
}
