// Filter consistency on simulated data: the NEES averaged over Monte-Carlo runs lies within its
// chi-square bounds, and the biases converge to the truth.
#include <catch2/catch.hpp>

#include <vector>

#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

// IMU errors of a MEMS unit, 15 ms clock offset, and a filter told exactly those.
ImuErrors mems_imu() {
  ImuErrors e;
  e.gyro_noise_radps_rthz = 2e-3;
  e.accel_noise_mps2_rthz = 2e-2;
  e.gyro_bias_walk_radps_rths = 2e-5;
  e.accel_bias_walk_mps2_rths = 5e-4;
  e.gyro_bias0_sigma_radps = 0.01;
  e.accel_bias0_sigma_mps2 = 0.1;
  e.time_offset_s = 0.015;
  return e;
}

PredictorOptions matching_options(const ImuErrors& e) {
  PredictorOptions o;
  o.imu_noise = {e.gyro_noise_radps_rthz, e.accel_noise_mps2_rthz, e.gyro_bias_walk_radps_rths,
                 e.accel_bias_walk_mps2_rths, 0};
  o.imu_time_offset_s = e.time_offset_s;
  o.initial_gyro_bias_radps = e.gyro_bias0_sigma_radps;
  o.initial_accel_bias_mps2 = e.accel_bias0_sigma_mps2;
  return o;
}

NavState truth_with_biases(const Trajectory& traj, const ImuRun& imu, std::size_t k, double t_cam) {
  NavState x = traj.at(t_cam).x;
  x.gyro_bias_radps = imu.gyro_bias[k];
  x.accel_bias_mps2 = imu.accel_bias[k];
  return x;
}

}  // namespace

TEST_CASE("NEES averaged over 20 runs stays within its 99% chi-square bounds (late 30 Hz vision, 1 kHz IMU)") {
  const int runs = 20;
  const std::vector<double> checkpoints_s{1.0, 2.0, 3.0};
  std::vector<double> nees_full(checkpoints_s.size(), 0.0), nees_pose(checkpoints_s.size(), 0.0);
  const Trajectory traj;
  const ImuErrors errors = mems_imu();
  const Matrix6d vision_cov = pose_cov(0.003, 0.004);
  std::uint64_t applied = 0, gated = 0;
  for (int run = 0; run < runs; ++run) {
    const ImuRun imu = simulate_imu(traj, errors, 0.0, checkpoints_s.back() + 0.001, 1000 + run);
    auto predictor = Predictor::create(matching_options(errors));
    REQUIRE(predictor);
    std::mt19937_64 rng(5000 + run);
    std::size_t next = 0;
    run_scenario(*predictor, traj, imu, errors.time_offset_s, 0.05, 30.0, 0.04, vision_cov, rng,
                 [&](std::size_t k, double t_cam) {
                   if (next >= checkpoints_s.size() || t_cam < checkpoints_s[next] - 1e-9) return;
                   const auto x = predictor->state();
                   REQUIRE(x);
                   const ErrorVector e = error_between(truth_with_biases(traj, imu, k, t_cam), *x);
                   const ErrorCovariance& P = predictor->covariance();
                   nees_full[next] += e.dot(P.ldlt().solve(e));
                   // Pose NEES in the vision convention (left perturbation of cam_T_obj).
                   const auto pred = predictor->predict(t_cam);
                   REQUIRE(pred);
                   const Vector6d xi = geometry::se3_log(traj.at(t_cam).x.cam_T_obj() * pred->cam_T_obj.inverse());
                   nees_pose[next] += xi.dot(pred->covariance.ldlt().solve(xi));
                   ++next;
                 });
    REQUIRE(next == checkpoints_s.size());
    const PredictorCounters c = predictor->status(checkpoints_s.back()).counters;
    applied += c.vision_applied;
    gated += c.vision_gated;
  }
  // The gate is at p = 0.999: a consistent filter gates about one correct pose in a thousand.
  INFO("gated " << gated << " of " << applied + gated);
  CHECK(applied > runs * 80);  // ~29 poses per second of each run
  CHECK(gated <= (applied + gated) / 200);
  for (std::size_t i = 0; i < checkpoints_s.size(); ++i) {
    const double full = nees_full[i] / runs, pose = nees_pose[i] / runs;
    const double lo17 = chi2_quantile(0.005, runs * 17.0) / runs, hi17 = chi2_quantile(0.995, runs * 17.0) / runs;
    const double lo6 = chi2_quantile(0.005, runs * 6.0) / runs, hi6 = chi2_quantile(0.995, runs * 6.0) / runs;
    INFO("t = " << checkpoints_s[i] << " s: mean NEES " << full << " in [" << lo17 << ", " << hi17 << "], pose "
                << pose << " in [" << lo6 << ", " << hi6 << "]");
    WARN("t = " << checkpoints_s[i] << " s: mean NEES " << full << " (17 dof), pose " << pose << " (6 dof)");
    CHECK(full > lo17);
    CHECK(full < hi17);
    CHECK(pose > lo6);
    CHECK(pose < hi6);
  }
}

TEST_CASE("gyro and accelerometer biases converge to the truth within their reported uncertainty") {
  const Trajectory traj;
  ImuErrors errors = mems_imu();
  errors.gyro_bias0_sigma_radps = 0;
  errors.accel_bias0_sigma_mps2 = 0;
  errors.gyro_bias0_radps = Eigen::Vector3d(0.015, -0.01, 0.02);
  errors.accel_bias0_mps2 = Eigen::Vector3d(-0.15, 0.2, 0.1);
  PredictorOptions options = matching_options(errors);
  options.initial_gyro_bias_radps = 0.03;
  options.initial_accel_bias_mps2 = 0.3;
  auto predictor = Predictor::create(options);
  REQUIRE(predictor);
  const double duration_s = 8;
  const ImuRun imu = simulate_imu(traj, errors, 0.0, duration_s, 77);
  std::mt19937_64 rng(78);
  run_scenario(*predictor, traj, imu, errors.time_offset_s, 0.05, 30.0, 0.04, pose_cov(0.003, 0.004), rng,
               [](std::size_t, double) {});
  const auto x = predictor->state();
  REQUIRE(x);
  const ErrorCovariance& P = predictor->covariance();
  const Eigen::Vector3d eg = imu.gyro_bias.back() - x->gyro_bias_radps;
  const Eigen::Vector3d ea = imu.accel_bias.back() - x->accel_bias_mps2;
  INFO("gyro bias error " << eg.transpose() << " sigma " << P.diagonal().segment<3>(err::bg).cwiseSqrt().transpose());
  INFO("accel bias error " << ea.transpose() << " sigma " << P.diagonal().segment<3>(err::ba).cwiseSqrt().transpose());
  for (int i = 0; i < 3; ++i) {
    CHECK(std::abs(eg[i]) < 4 * std::sqrt(P(err::bg + i, err::bg + i)));
    CHECK(std::abs(ea[i]) < 4 * std::sqrt(P(err::ba + i, err::ba + i)));
  }
  // Converged, not merely uncertain: a tenth of the initial bias for the gyro, a fifth for the
  // accelerometer (observable only through the rotation of the walk).
  CHECK(eg.norm() < 0.1 * errors.gyro_bias0_radps.norm());
  CHECK(ea.norm() < 0.2 * errors.accel_bias0_mps2.norm());
}
