// The vision error as a filter state (PredictorOptions::vision_error_time_s): poses whose errors
// are mostly shared from frame to frame, as a tracker's are (the same edges seen from nearly the
// same place), give a consistent NIS and an honest pose covariance when the filter carries the
// shared part, and an overconfident pose when it takes every pose's whole covariance as new noise.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "epichead/fusion/imu_filter.h"
#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

constexpr double kTimeConstantS = 1.0;

PredictorOptions quiet_imu_options(double vision_error_time_s) {
  PredictorOptions o;
  o.imu_noise = {2e-3, 2e-2, 2e-5, 5e-4, 0};
  o.initial_gyro_bias_radps = 0.01;
  o.initial_accel_bias_mps2 = 0.1;
  o.vision_error_time_s = vision_error_time_s;
  o.unaided.enabled = false;
  return o;
}

struct Stats {
  double nis_sum = 0;
  int nis_count = 0;
  double nees_sum = 0;  // the predicted pose against the truth, with its covariance
  int nees_count = 0;
  int gated = 0;
};

// One run: 30 Hz poses, 40 ms late, each off by a shared error (object frame, first-order
// Gauss-Markov with kTimeConstantS and stationary covariance C_obj) and its own noise W (camera
// frame). The predictor is told cov = Ad C Ad' + W with the correlated part Ad C Ad'.
void run(PredictorOptions options, std::uint64_t seed, Stats& stats) {
  const Trajectory traj;
  ImuErrors errors;
  errors.gyro_noise_radps_rthz = 2e-3;
  errors.accel_noise_mps2_rthz = 2e-2;
  errors.gyro_bias_walk_radps_rths = 2e-5;
  errors.accel_bias_walk_mps2_rths = 5e-4;
  errors.gyro_bias0_sigma_radps = 0.01;
  errors.accel_bias0_sigma_mps2 = 0.1;
  const double duration_s = 4.0, rate_hz = 30, latency_s = 0.04, first_s = 0.1;
  const ImuRun imu = simulate_imu(traj, errors, 0.0, duration_s, seed);
  auto predictor = Predictor::create(options);
  REQUIRE(predictor);
  std::mt19937_64 rng(seed + 1);
  std::normal_distribution<double> n01;
  const Matrix6d C_obj = pose_cov(0.004, 0.004);
  const Matrix6d W = pose_cov(0.0004, 0.0004);
  const Eigen::LLT<Matrix6d> C_llt(C_obj), W_llt(W);
  const auto draw = [&](const Eigen::LLT<Matrix6d>& llt) {
    Vector6d z;
    for (int i = 0; i < 6; ++i) z[i] = n01(rng);
    return Vector6d(llt.matrixL() * z);
  };
  Vector6d shared = draw(C_llt);
  const double a = std::exp(-1.0 / (rate_hz * kTimeConstantS));
  int j = 0;
  for (const ImuSample& s : imu.samples) {
    predictor->add_imu(s);
    for (;;) {
      const double t_exp = first_s + j / rate_hz;
      if (t_exp + latency_s > s.t_s) break;
      if (j > 0) shared = a * shared + std::sqrt(1 - a * a) * draw(C_llt);
      ++j;
      const Eigen::Isometry3d truth = traj.at(t_exp).x.cam_T_obj();
      const Eigen::Isometry3d measured = geometry::se3_exp(draw(W_llt)) * truth * geometry::se3_exp(shared);
      const Matrix6d Ad = geometry::se3_adjoint(measured);
      const Matrix6d correlated = Ad * C_obj * Ad.transpose();
      // The predicted pose against the truth before this pose is taken.
      if (const auto pred = predictor->predict(t_exp); pred && t_exp > 1.0) {
        const Vector6d e = geometry::se3_log(truth * pred->cam_T_obj.inverse());
        stats.nees_sum += e.dot(pred->covariance.ldlt().solve(e));
        ++stats.nees_count;
      }
      const VisionResult r = predictor->add_vision(t_exp, measured, correlated + W, correlated);
      if (t_exp > 1.0 && (r.verdict == VisionVerdict::Applied || r.verdict == VisionVerdict::Gated)) {
        stats.nis_sum += r.mahalanobis2;
        ++stats.nis_count;
        stats.gated += r.verdict == VisionVerdict::Gated;
      }
    }
  }
}

}  // namespace

TEST_CASE("carrying the shared vision error gives a consistent NIS and an honest pose covariance") {
  Stats carried, white;
  for (int k = 0; k < 8; ++k) {
    run(quiet_imu_options(kTimeConstantS), 100 + k, carried);
    run(quiet_imu_options(0), 100 + k, white);
  }
  REQUIRE(carried.nis_count > 600);
  const double nis_carried = carried.nis_sum / carried.nis_count, nis_white = white.nis_sum / white.nis_count;
  const double nees_carried = carried.nees_sum / carried.nees_count, nees_white = white.nees_sum / white.nees_count;
  INFO("NIS mean carried " << nis_carried << ", white " << nis_white << "; pose NEES mean carried " << nees_carried
                           << ", white " << nees_white << "; gated " << carried.gated << " of " << carried.nis_count);
  // chi-square, 6 dof: mean 6. The innovations of successive poses are independent only when the
  // shared error is carried; taken as new noise each frame it makes S far too large.
  CHECK(nis_carried > 5.0);
  CHECK(nis_carried < 7.0);
  CHECK(nis_white < 3.0);
  // The pose itself is only as good as the shared error lets it be: carried, the filter says so;
  // averaging the poses as if independent, it claims far more.
  CHECK(nees_carried > 4.5);
  CHECK(nees_carried < 7.5);
  CHECK(nees_white > 15.0);
  CHECK(carried.gated <= carried.nis_count / 100);
}

TEST_CASE("without poses the vision error keeps its stationary covariance") {
  PredictorOptions options = quiet_imu_options(kTimeConstantS);
  ImuFilter filter(options);
  const Trajectory traj;
  const ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 1.0, 7);
  std::size_t k = 0;
  for (; imu.samples[k].t_s < 0.2; ++k) filter.add(imu.samples[k]);
  const Eigen::Isometry3d pose = traj.at(0.2).x.cam_T_obj();
  const Matrix6d correlated = pose_cov(0.004, 0.006);
  REQUIRE(filter.initialise(0.2, pose, correlated + pose_cov(0.001, 0.001), correlated));
  const Matrix6d Ad_inv = geometry::se3_adjoint(pose.inverse());
  const Matrix6d stationary = Ad_inv * correlated * Ad_inv.transpose();
  for (; k < imu.samples.size(); ++k) filter.add(imu.samples[k]);
  const StateEntry* e = filter.newest_state();
  REQUIRE(e);
  const Matrix6d P_vision = e->P.block<6, 6>(err::vision, err::vision);
  INFO("P_vision\n" << P_vision << "\nstationary\n" << stationary);
  CHECK((P_vision - stationary).cwiseAbs().maxCoeff() < 1e-9 * stationary.cwiseAbs().maxCoeff());
}

TEST_CASE("a correlated covariance that is not a part of the pose's covariance is bad input") {
  PredictorOptions options = quiet_imu_options(kTimeConstantS);
  auto predictor = Predictor::create(options);
  REQUIRE(predictor);
  for (int k = 0; k <= 200; ++k)
    predictor->add_imu({k * 0.001, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, standard_gravity_mps2)});
  const Eigen::Isometry3d pose = Eigen::Translation3d(0, 0, 0.5) * Eigen::Isometry3d::Identity();
  const Matrix6d cov = pose_cov(0.004, 0.004);
  // The whole covariance shared: nothing left for the pose's own noise.
  CHECK(predictor->add_vision(0.1, pose, cov, cov).verdict == VisionVerdict::BadInput);
  // Not positive semi-definite.
  CHECK(predictor->add_vision(0.1, pose, cov, -0.5 * cov).verdict == VisionVerdict::BadInput);
  Matrix6d nan = 0.5 * cov;
  nan(2, 2) = std::nan("");
  CHECK(predictor->add_vision(0.1, pose, cov, nan).verdict == VisionVerdict::BadInput);
  CHECK(predictor->add_vision(0.1, pose, cov, 0.5 * cov).verdict == VisionVerdict::Initialised);
  CHECK(predictor->status(0.2).counters.vision_bad_input == 3);
}
