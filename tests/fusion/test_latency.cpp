// Late vision poses: applied at their exposure time with re-propagation of the buffered samples,
// which gives the same state as processing in order; poses older than the buffer or than the last
// applied pose are rejected and counted; predict() works between samples and beyond the newest.
#include <catch2/catch.hpp>

#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

ImuErrors noisy_imu() {
  ImuErrors e;
  e.gyro_noise_radps_rthz = 2e-3;
  e.accel_noise_mps2_rthz = 2e-2;
  e.gyro_bias0_sigma_radps = 0.01;
  e.accel_bias0_sigma_mps2 = 0.1;
  e.time_offset_s = 0.012;
  return e;
}

PredictorOptions options_for(const ImuErrors& e) {
  PredictorOptions o;
  o.imu_time_offset_s = e.time_offset_s;
  return o;
}

// Runs the scenario with a given vision latency and returns the final state.
NavState final_state(double latency_s, std::uint64_t* repropagated = nullptr) {
  const Trajectory traj;
  const ImuErrors errors = noisy_imu();
  const ImuRun imu = simulate_imu(traj, errors, 0.0, 2.0, 11);
  auto predictor = Predictor::create(options_for(errors));
  REQUIRE(predictor);
  std::mt19937_64 rng(12);
  run_scenario(*predictor, traj, imu, errors.time_offset_s, 0.05, 30.0, latency_s, pose_cov(0.003, 0.004), rng,
               [](std::size_t, double) {}, 1.9);
  if (repropagated) *repropagated = predictor->status(2.0).counters.repropagated_samples;
  return *predictor->state();
}

}  // namespace

TEST_CASE("a pose 80 ms late gives the same state as one applied as soon as its exposure time has passed") {
  std::uint64_t reprop_prompt = 0, reprop_late = 0;
  const NavState prompt = final_state(0.0, &reprop_prompt);
  const NavState late = final_state(0.08, &reprop_late);
  const ErrorVector d = error_between(prompt, late);
  INFO("difference " << d.transpose());
  CHECK(d.cwiseAbs().maxCoeff() < 1e-9);
  // And the late run really did re-propagate: ~80 samples per pose instead of ~1.
  CHECK(reprop_late > 50 * reprop_prompt / 2);
  CHECK(reprop_late > 4000);
}

TEST_CASE("poses older than the buffer or than the last applied pose are rejected and counted") {
  const Trajectory traj;
  const ImuErrors errors = noisy_imu();
  const ImuRun imu = simulate_imu(traj, errors, 0.0, 1.5, 21);
  PredictorOptions options = options_for(errors);
  options.buffer_s = 0.5;
  auto predictor = Predictor::create(options);
  REQUIRE(predictor);
  const Matrix6d cov = pose_cov(0.003, 0.004);
  for (const ImuSample& s : imu.samples) predictor->add_imu(s);
  REQUIRE(predictor->add_vision(1.2, traj.at(1.2).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  CHECK(predictor->add_vision(1.3, traj.at(1.3).x.cam_T_obj(), cov).verdict == VisionVerdict::Applied);
  // Older than the last applied pose.
  CHECK(predictor->add_vision(1.25, traj.at(1.25).x.cam_T_obj(), cov).verdict == VisionVerdict::OutOfOrder);
  CHECK(predictor->add_vision(1.3, traj.at(1.3).x.cam_T_obj(), cov).verdict == VisionVerdict::OutOfOrder);
  const PredictorCounters c = predictor->status(1.5).counters;
  CHECK(c.vision_out_of_order == 2);
  CHECK(c.vision_applied == 1);

  // A fresh filter initialised late, then a pose from before the buffered samples.
  auto second = Predictor::create(options);
  REQUIRE(second);
  for (const ImuSample& s : imu.samples) second->add_imu(s);
  REQUIRE(second->add_vision(1.4, traj.at(1.4).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  CHECK(second->add_vision(1.45, traj.at(1.45).x.cam_T_obj(), cov).verdict == VisionVerdict::Applied);
  // 1.5 s of samples in a 0.5 s ring: the oldest kept sample is at ~0.95 s.
  auto third = Predictor::create(options);
  REQUIRE(third);
  for (const ImuSample& s : imu.samples) third->add_imu(s);
  CHECK(third->add_vision(0.5, traj.at(0.5).x.cam_T_obj(), cov).verdict == VisionVerdict::NoImu);
  REQUIRE(third->add_vision(1.45, traj.at(1.45).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  third->reset();
  REQUIRE(third->add_vision(1.2, traj.at(1.2).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  for (int i = 0; i < 3; ++i) third->add_imu({1.6 + errors.time_offset_s + 0.1 * i, imu.samples.back().gyro_radps,
                                              imu.samples.back().accel_mps2});
  // The newest sample is now at 1.8 s: 0.9 s is far outside the ring.
  CHECK(third->add_vision(1.21, traj.at(1.21).x.cam_T_obj(), cov).verdict == VisionVerdict::Applied);
  auto fourth = Predictor::create(options);
  REQUIRE(fourth);
  for (const ImuSample& s : imu.samples) fourth->add_imu(s);
  REQUIRE(fourth->add_vision(1.4, traj.at(1.4).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  for (int i = 1; i <= 800; ++i)
    fourth->add_imu({1.5 + errors.time_offset_s + 0.001 * i, imu.samples.back().gyro_radps, imu.samples.back().accel_mps2});
  // Newest sample at 2.3 s, ring of ~0.55 s: 1.45 s has dropped out of it.
  CHECK(fourth->add_vision(1.45, traj.at(1.45).x.cam_T_obj(), cov).verdict == VisionVerdict::TooOld);
  CHECK(fourth->status(2.3).counters.vision_too_old == 1);
}

TEST_CASE("predict follows the truth between samples and beyond the newest, with growing covariance") {
  const Trajectory traj;
  ImuErrors errors;  // noiseless IMU, precise vision: the prediction error is the model's
  errors.time_offset_s = 0.02;
  const ImuRun imu = simulate_imu(traj, errors, 0.0, 2.0, 31);
  PredictorOptions options;
  options.imu_time_offset_s = errors.time_offset_s;
  auto predictor = Predictor::create(options);
  REQUIRE(predictor);
  CHECK_FALSE(predictor->predict(0.1));  // not initialised
  std::mt19937_64 rng(32);
  run_scenario(*predictor, traj, imu, errors.time_offset_s, 0.05, 30.0, 0.03, pose_cov(1e-4, 1e-4), rng,
               [](std::size_t, double) {});
  const double newest = 2.0;
  auto pose_error = [&](double t) {
    const auto p = predictor->predict(t);
    REQUIRE(p);
    return geometry::se3_log(traj.at(t).x.cam_T_obj() * p->cam_T_obj.inverse());
  };
  // Between samples, inside the buffer.
  const Vector6d between = pose_error(1.9805);
  CHECK(between.head<3>().norm() < 5e-4);
  CHECK(between.tail<3>().norm() < 5e-4);
  // 20 ms ahead with the last rates held: the trajectory's angular acceleration (~1 rad/s^2)
  // costs about 0.5 * 1 * 0.02^2 = 2e-4 rad.
  const Vector6d ahead = pose_error(newest + 0.02);
  CHECK(ahead.head<3>().norm() < 2e-3);
  CHECK(ahead.tail<3>().norm() < 2e-3);
  const auto near = predictor->predict(newest + 0.001), far = predictor->predict(newest + 0.05);
  REQUIRE(near);
  REQUIRE(far);
  CHECK(far->extrapolated_s == Approx(0.05));
  CHECK(far->covariance.trace() > near->covariance.trace());
  CHECK(near->extrapolated_s == Approx(0.001));
}

TEST_CASE("a pose ahead of the newest sample is applied there, older samples are then rejected") {
  const Trajectory traj;
  const ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 1.0, 41);
  auto predictor = Predictor::create(PredictorOptions{});
  REQUIRE(predictor);
  for (const ImuSample& s : imu.samples) predictor->add_imu(s);
  const Matrix6d cov = pose_cov(0.003, 0.004);
  REQUIRE(predictor->add_vision(0.9, traj.at(0.9).x.cam_T_obj(), cov).verdict == VisionVerdict::Initialised);
  CHECK(predictor->add_vision(1.005, traj.at(1.005).x.cam_T_obj(), cov).verdict == VisionVerdict::Applied);
  CHECK(predictor->state_t_s() == Approx(1.005));
  const ImuSample late{1.003, imu.samples.back().gyro_radps, imu.samples.back().accel_mps2};
  CHECK(predictor->add_imu(late) == ImuVerdict::OutOfOrder);
  const ImuSample next{1.006, imu.samples.back().gyro_radps, imu.samples.back().accel_mps2};
  CHECK(predictor->add_imu(next) == ImuVerdict::Accepted);
  CHECK(predictor->state_t_s() == Approx(1.006));
}
