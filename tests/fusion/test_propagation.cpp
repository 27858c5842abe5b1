// IMU propagation: the nominal state follows the truth on exact readings; the block-sparse
// covariance step equals the dense F P F' + Q it stands for.
#include <catch2/catch.hpp>

#include "epichead/fusion/imu_propagation.h"
#include "epichead/geometry/so3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

ImuSample exact_sample(const Trajectory& traj, double t, const Eigen::Vector3d& bg, const Eigen::Vector3d& ba) {
  const TruthPoint p = traj.at(t);
  const Eigen::Matrix3d imu_R_cam = traj.params().cam_R_imu.transpose();
  return {t, imu_R_cam * p.gyro_cam_radps + bg, imu_R_cam * p.force_cam_mps2 + ba};
}

}  // namespace

TEST_CASE("noiseless propagation reproduces the true trajectory, with a rotated IMU and known biases") {
  TrajectoryParams params;
  params.cam_R_imu = geometry::so3_exp(Eigen::Vector3d(0.3, -1.2, 0.7));
  const Trajectory traj(params);
  const Eigen::Vector3d bg(0.01, -0.02, 0.005), ba(0.1, 0.05, -0.2);
  NavState x = traj.at(0).x;
  x.gyro_bias_radps = bg;
  x.accel_bias_mps2 = ba;
  ErrorCovariance P = ErrorCovariance::Identity();
  ImuMount mount{params.cam_R_imu};
  ImuSample prev = exact_sample(traj, 0, bg, ba);
  const double rate_hz = 1000, duration_s = 3;
  for (int k = 1; k <= duration_s * rate_hz; ++k) {
    const ImuSample s = exact_sample(traj, k / rate_hz, bg, ba);
    propagate(x, P, prev, s, mount, ImuNoise{});
    prev = s;
  }
  const NavState truth = traj.at(duration_s).x;
  const ErrorVector e = error_between(truth, x);
  // Dead reckoning for 3 s on perfect readings: the midpoint rule leaves micro-metres.
  CHECK(e.segment<3>(err::theta).norm() < 1e-6);
  CHECK(e.segment<3>(err::v).norm() < 1e-5);
  CHECK(e.segment<3>(err::p).norm() < 2e-5);
  CHECK((x.cam_T_obj().matrix() - truth.cam_T_obj().matrix()).cwiseAbs().maxCoeff() < 2e-5);
}

TEST_CASE("the block-sparse covariance step equals the dense F P F' + Q") {
  const Trajectory traj;
  NavState x = traj.at(0.4).x;
  x.gyro_bias_radps = Eigen::Vector3d(0.01, 0.02, -0.03);
  x.accel_bias_mps2 = Eigen::Vector3d(-0.1, 0.2, 0.05);
  const Eigen::Matrix3d C = geometry::so3_exp(Eigen::Vector3d(0.2, 0.1, -0.4));
  const ImuMount mount{C};
  ImuNoise noise;
  noise.gravity_walk_rad_rths = 1e-3;
  // A random symmetric positive definite P.
  ErrorCovariance A = ErrorCovariance::Random();
  const ErrorCovariance P0 = A * A.transpose() + ErrorCovariance::Identity();
  const ImuSample s0{0.4, Eigen::Vector3d(0.5, -1.0, 2.0), Eigen::Vector3d(1.0, -9.0, 2.0)};
  const ImuSample s1{0.402, Eigen::Vector3d(0.6, -0.9, 2.1), Eigen::Vector3d(1.2, -9.1, 1.8)};
  const double dt = s1.t_s - s0.t_s;

  NavState xp = x;
  ErrorCovariance P = P0;
  propagate(xp, P, s0, s1, mount, noise);

  // The transition written out densely (docs/fusion.md).
  const Eigen::Vector3d omega = C * (0.5 * (s0.gyro_radps + s1.gyro_radps) - x.gyro_bias_radps);
  const Eigen::Vector3d f_mid = C * (0.5 * (s0.accel_mps2 + s1.accel_mps2) - x.accel_bias_mps2);
  ErrorCovariance F = ErrorCovariance::Identity();
  F.block<3, 3>(err::theta, err::theta) = geometry::so3_exp(omega * dt).transpose();
  F.block<3, 3>(err::theta, err::bg) = -C * dt;
  F.block<3, 3>(err::p, err::v) = Eigen::Matrix3d::Identity() * dt;
  F.block<3, 3>(err::v, err::theta) = -x.obj_R_cam * geometry::skew(f_mid) * dt;
  F.block<3, 3>(err::v, err::ba) = -x.obj_R_cam * C * dt;
  F.block<3, 2>(err::v, err::grav) = gravity_jacobian(x) * dt;
  ErrorVector q;
  q << Eigen::Vector3d::Constant(noise.gyro_noise_radps_rthz * noise.gyro_noise_radps_rthz),
      Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(noise.accel_noise_mps2_rthz * noise.accel_noise_mps2_rthz),
      Eigen::Vector3d::Constant(noise.gyro_bias_walk_radps_rths * noise.gyro_bias_walk_radps_rths),
      Eigen::Vector3d::Constant(noise.accel_bias_walk_mps2_rths * noise.accel_bias_walk_mps2_rths),
      Eigen::Vector2d::Constant(noise.gravity_walk_rad_rths * noise.gravity_walk_rad_rths);
  const ErrorCovariance expected = F * P0 * F.transpose() + ErrorCovariance(q.asDiagonal()) * dt;
  CHECK((P - expected).cwiseAbs().maxCoeff() < 1e-12 * expected.cwiseAbs().maxCoeff());
}

TEST_CASE("the transition matches numerical differentiation of the nominal step") {
  // Perturb each error component, propagate the nominal state, and compare the propagated error
  // with F * perturbation (first order).
  const Trajectory traj;
  NavState x = traj.at(1.0).x;
  x.gyro_bias_radps = Eigen::Vector3d(0.01, 0.02, -0.03);
  const ImuMount mount{geometry::so3_exp(Eigen::Vector3d(0.2, 0.1, -0.4))};
  const ImuSample s0{1.0, Eigen::Vector3d(0.5, -1.0, 2.0), Eigen::Vector3d(1.0, -9.0, 2.0)};
  const ImuSample s1{1.01, Eigen::Vector3d(0.5, -1.0, 2.0), Eigen::Vector3d(1.0, -9.0, 2.0)};
  NavState ref = x;
  ErrorCovariance P = ErrorCovariance::Zero();
  propagate(ref, P, s0, s1, mount, ImuNoise{});
  // With P = 0 and zero noise the step leaves P at 0; get F column by column from P = e_i e_i'.
  const double h = 1e-6;
  for (int i = 0; i < err::dim; ++i) {
    ErrorVector d = ErrorVector::Zero();
    d[i] = h;
    NavState xi = x;
    inject(xi, d);
    ErrorCovariance Pi = ErrorCovariance::Zero();
    propagate(xi, Pi, s0, s1, mount, ImuNoise{});
    const ErrorVector numeric = error_between(xi, ref) / h;
    ErrorCovariance Pe = ErrorCovariance::Zero();
    Pe(i, i) = 1;
    NavState tmp = x;
    propagate(tmp, Pe, s0, s1, mount, ImuNoise{});
    // Pe = F e_i e_i' F' = f f' with f = F e_i; f_i component gives the scale: f = Pe.col(i) / sqrt(Pe(i,i)).
    const ErrorVector column = Pe.col(i) / std::sqrt(Pe(i, i));
    INFO("error component " << i);
    // The filter keeps only first-order terms in dt: the second-order ones are ~dt^2 = 1e-4.
    CHECK((numeric - column).cwiseAbs().maxCoeff() < 2e-3);
  }
}

TEST_CASE("interpolate is linear between samples and holds the ends outside") {
  const ImuSample a{1.0, Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6)};
  const ImuSample b{1.002, Eigen::Vector3d(3, 2, 1), Eigen::Vector3d(6, 5, 4)};
  const ImuSample m = interpolate(a, b, 1.0005);
  CHECK(m.t_s == 1.0005);
  CHECK(m.gyro_radps.isApprox(Eigen::Vector3d(1.5, 2, 2.5)));
  CHECK(m.accel_mps2.isApprox(Eigen::Vector3d(4.5, 5, 5.5)));
  CHECK(interpolate(a, b, 2.0).gyro_radps == b.gyro_radps);
  CHECK(interpolate(a, b, 0.0).accel_mps2 == a.accel_mps2);
}
