// The camera-IMU offset's uncertainty (PredictorOptions::imu_time_offset_sigma_s): with the
// offset wrong by 15 ms and the camera turning at up to ~1 rad/s, sharp poses disagree with the
// IMU-propagated state by more than their own covariance says, so they are gated and the filter
// coasts; told how uncertain the offset is, it takes them with the covariance the timing error
// really adds along the motion. The price: a constant offset is an error the filter cannot
// average away, and weighing the poses less lets it wander further in the bursts (measured:
// 0.004 rad at the end with sigma 0 and most poses taken, 0.021 rad with 15 ms). The tracker
// uses it only until the offset is estimated (tools/track_prediction.cpp), where not losing
// the poses is what matters.
#include <catch2/catch.hpp>

#include "epichead/fusion/predictor.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
using namespace epichead::fusion::testing;

namespace {

struct Outcome {
  std::uint64_t applied = 0, gated = 0;
  double final_rotation_error_rad = 0;
};

// Faster turns than the default trajectory: peaks of about 1.5 rad/s, as in walking bursts.
TrajectoryParams fast_turns() {
  TrajectoryParams p;
  p.angle_amp_rad = {0.5, 0.4, 0.3};
  p.angle_freq_radps = {2.6, 3.1, 3.7};
  return p;
}

Outcome run_with_sigma(double sigma_s) {
  const Trajectory traj(fast_turns());
  ImuErrors errors;
  errors.gyro_noise_radps_rthz = 2e-3;
  errors.accel_noise_mps2_rthz = 2e-2;
  errors.time_offset_s = 0.015;  // the truth; the predictor is told 0
  const ImuRun imu = simulate_imu(traj, errors, 0.0, 4.0, 21);
  PredictorOptions o;
  o.imu_time_offset_s = 0;
  o.imu_time_offset_sigma_s = sigma_s;
  auto predictor = Predictor::create(o);
  REQUIRE(predictor);
  std::mt19937_64 rng(22);
  run_scenario(*predictor, traj, imu, errors.time_offset_s, 0.05, 30.0, 0.03, pose_cov(0.001, 0.001), rng,
               [](std::size_t, double) {}, 3.9);
  Outcome out;
  const auto c = predictor->status(4.0).counters;
  out.applied = c.vision_applied;
  out.gated = c.vision_gated;
  const auto p = predictor->predict(3.9);
  REQUIRE(p);
  out.final_rotation_error_rad =
      Eigen::AngleAxisd(p->cam_T_obj.linear() * traj.at(3.9).x.cam_T_obj().linear().transpose()).angle();
  return out;
}

}  // namespace

TEST_CASE("an uncertain camera-IMU offset widens the poses along the motion instead of gating them",
          "[fusion][time_offset]") {
  const Outcome exact = run_with_sigma(0.0);
  const Outcome told = run_with_sigma(0.015);
  INFO("sigma 0: applied " << exact.applied << " gated " << exact.gated << " error " << exact.final_rotation_error_rad
                           << "; sigma 15 ms: applied " << told.applied << " gated " << told.gated << " error "
                           << told.final_rotation_error_rad);
  CHECK(exact.gated > exact.applied / 5);  // a 15 ms error at ~1.5 rad/s is many sigmas of a 1 mrad pose
  CHECK(told.gated * 3 < exact.gated);     // measured 6 against 23
  CHECK(told.applied > exact.applied);
  CHECK(told.final_rotation_error_rad < 0.035);
}

TEST_CASE("the offset's uncertainty must be finite and at most a second", "[fusion][time_offset]") {
  PredictorOptions o;
  o.imu_time_offset_sigma_s = -0.001;
  CHECK_FALSE(Predictor::create(o));
  o.imu_time_offset_sigma_s = NAN;
  CHECK_FALSE(Predictor::create(o));
  o.imu_time_offset_sigma_s = 2;
  CHECK_FALSE(Predictor::create(o));
  o.imu_time_offset_sigma_s = 0.02;
  CHECK(Predictor::create(o));
}
