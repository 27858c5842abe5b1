#include <catch2/catch.hpp>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "epichead/sim/head_mount.h"
#include "epichead/sim/imu_model.h"
#include "epichead/sim/trajectory.h"

using namespace epichead::sim;

namespace {

constexpr double deg = std::numbers::pi / 180.0;

// The camera of a walking robot with the head at fixed angles: the lever arm from the body's
// rotation centre to the camera makes the accelerometer see centripetal and tangential terms.
std::function<Kinematics(double)> walking_camera(double jerk) {
  WalkingParams p;
  p.jerk = jerk;
  p.seed = 5;
  auto body = std::make_shared<Trajectory>(Trajectory::walking(p));
  HeadMount mount;
  mount.cam_misalign_rad = {0.01, 0.02, -0.01};
  HeadAngles head;
  head.pan_rad = 0.4;
  head.tilt_rad = 0.25;
  return [body, mount, head](double t) { return compose(body->at(t), body_T_cam(mount, head)); };
}

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& phi) {
  const double a = phi.norm();
  if (a == 0) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(a, phi / a).toRotationMatrix();
}

}  // namespace

TEST_CASE("integrating the noiseless IMU reproduces the true camera motion over 5 s", "[sim][imu]") {
  // Tolerance after 5 s of walking at jerk 2 (bursts to 160 deg/s, 1 kHz samples): 1e-8 rad in
  // orientation, 5e-6 m/s in velocity, 1e-6 m in position. The integrator is fourth order
  // (trapezoid with derivative end corrections, cubic Hermite for position), so what remains is
  // its own error; a wrong IMU value (a missing lever-arm or Coriolis term, a frame mix-up)
  // gives errors of millimetres to metres.
  const auto cam = walking_camera(2.0);
  const ImuRun run = simulate_imu(ImuParams{}, 1, cam, 0.0, 5.0);
  REQUIRE(run.samples.size() == 5001);
  const auto& s = run.samples;
  const std::size_t n = s.size();
  const double h = 1e-3;
  // Central differences for the end corrections: integration runs from sample 2 to n - 3.
  auto deriv = [h](const std::vector<Eigen::Vector3d>& x, std::size_t k) { return ((x[k + 1] - x[k - 1]) / (2 * h)).eval(); };
  std::vector<Eigen::Vector3d> w(n);
  for (std::size_t k = 0; k < n; ++k) w[k] = s[k].gyro_radps;
  std::vector<Eigen::Matrix3d> R(n, Eigen::Matrix3d::Identity());
  R[1] = cam(s[1].t_true_s).pose.linear();
  for (std::size_t k = 1; k + 2 < n; ++k) {
    const Eigen::Vector3d phi =
        h * (0.5 * (w[k] + w[k + 1]) + h / 12 * (deriv(w, k) - deriv(w, k + 1))) + h * h / 12 * w[k].cross(w[k + 1]);
    R[k + 1] = R[k] * exp_so3(phi);
  }
  // World acceleration from the specific force and the integrated orientation.
  std::vector<Eigen::Vector3d> a(n, Eigen::Vector3d::Zero());
  for (std::size_t k = 1; k + 2 < n; ++k) a[k] = R[k] * s[k].accel_mps2 + gravity_world();
  const Kinematics k0 = cam(s[2].t_true_s);
  Eigen::Vector3d v = k0.vel_mps, p = k0.pose.translation();
  std::size_t last = 2;
  for (std::size_t k = 2; k + 3 < n; ++k) {
    const Eigen::Vector3d d0 = deriv(a, k), d1 = deriv(a, k + 1);
    p += v * h + h * h * (7.0 / 20 * a[k] + 3.0 / 20 * a[k + 1] + h / 20 * d0 - h / 30 * d1);
    v += h * (0.5 * (a[k] + a[k + 1]) + h / 12 * (d0 - d1));
    last = k + 1;
  }
  const Kinematics k1 = cam(s[last].t_true_s);
  const double rot_err = Eigen::AngleAxisd(R[last].transpose() * k1.pose.linear()).angle();
  INFO("rotation error " << rot_err << " rad, velocity error " << (v - k1.vel_mps).norm() << " m/s, position error "
                         << (p - k1.pose.translation()).norm() << " m");
  CHECK(rot_err < 1e-8);
  CHECK((v - k1.vel_mps).norm() < 5e-6);
  CHECK((p - k1.pose.translation()).norm() < 1e-6);
  // The motion is not trivial: the camera moved and turned.
  CHECK((k1.pose.translation() - k0.pose.translation()).norm() > 0.1);
  CHECK(run.samples[1800].gyro_true_radps.norm() > 1.0);
}

TEST_CASE("an IMU at rest measures gravity as upward specific force in the camera frame", "[sim][imu]") {
  // Camera looking horizontally along world x: camera y (down) is world -z.
  Kinematics still;
  still.pose.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Vector3d gyro, accel;
  true_imu(still, gyro, accel);
  CHECK(gyro.norm() == 0.0);
  CHECK((accel - Eigen::Vector3d(0, -standard_gravity_mps2, 0)).norm() < 1e-12);
}

TEST_CASE("IMU samples lie on the device clock grid, offset and drifting against true time", "[sim][imu]") {
  ImuParams p;
  p.clock_offset_s = 0.0123;
  p.clock_drift = 200e-6;
  const ImuRun run = simulate_imu(p, 1, walking_camera(1), 0.0, 2.0);
  REQUIRE(!run.samples.empty());
  for (const ImuSample& s : run.samples) {
    CHECK(s.t_device_s == Approx(p.clock_offset_s + (1 + p.clock_drift) * s.t_true_s).margin(1e-12));
    CHECK(std::abs(s.t_device_s * 1000 - std::round(s.t_device_s * 1000)) < 1e-6);
    CHECK(s.t_true_s >= 0.0);
    CHECK(s.t_true_s <= 2.0);
  }
  CHECK(run.samples[1].t_device_s - run.samples[0].t_device_s == Approx(1e-3));
}

TEST_CASE("IMU white noise has the standard deviation its density gives at the sample rate", "[sim][imu]") {
  ImuParams p;
  p.gyro_noise_radps_rthz = 0.003;
  p.accel_noise_mps2_rthz = 0.02;
  const ImuRun run = simulate_imu(p, 9, walking_camera(1), 0.0, 20.0);
  double sg = 0, sa = 0;
  for (const ImuSample& s : run.samples) {
    sg += (s.gyro_radps - s.gyro_true_radps).squaredNorm();
    sa += (s.accel_mps2 - s.accel_true_mps2).squaredNorm();
  }
  const double n = 3.0 * static_cast<double>(run.samples.size());
  CHECK(std::sqrt(sg / n) == Approx(0.003 * std::sqrt(1000.0)).epsilon(0.02));
  CHECK(std::sqrt(sa / n) == Approx(0.02 * std::sqrt(1000.0)).epsilon(0.02));
}

TEST_CASE("IMU bias and scale errors are drawn once per run and applied to every sample", "[sim][imu]") {
  ImuParams p;
  p.gyro_bias_radps = 0.01;
  p.accel_bias_mps2 = 0.05;
  p.gyro_scale_error = 0.01;
  p.accel_scale_error = 0.01;
  const ImuRun run = simulate_imu(p, 4, walking_camera(1), 0.0, 3.0);
  REQUIRE(run.gyro_bias0_radps.norm() > 0);
  REQUIRE((run.gyro_scale - Eigen::Vector3d::Ones()).norm() > 0);
  for (const ImuSample& s : run.samples) {
    CHECK((s.gyro_radps - (run.gyro_scale.cwiseProduct(s.gyro_true_radps) + run.gyro_bias0_radps)).norm() < 1e-12);
    CHECK((s.accel_mps2 - (run.accel_scale.cwiseProduct(s.accel_true_mps2) + run.accel_bias0_mps2)).norm() < 1e-12);
  }
}

TEST_CASE("IMU bias random walk spreads as sqrt(time)", "[sim][imu]") {
  ImuParams p;
  p.gyro_bias_walk_radps_rths = 0.001;
  // Many short independent runs: the bias after 4 s has standard deviation 0.001 * sqrt(4).
  double sum_sq = 0;
  int n = 0;
  Kinematics still;
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    const ImuRun run = simulate_imu(p, seed, [&](double) { return still; }, 0.0, 4.0);
    sum_sq += run.samples.back().gyro_radps.squaredNorm();
    n += 3;
  }
  CHECK(std::sqrt(sum_sq / n) == Approx(0.002).epsilon(0.25));
}

TEST_CASE("IMU saturation clips to the range and counts the clipped samples", "[sim][imu]") {
  ImuParams p;
  p.gyro_range_radps = 20 * deg;  // the walking bursts reach 30-80 deg/s
  const ImuRun run = simulate_imu(p, 1, walking_camera(1), 0.0, 5.0);
  double largest = 0;
  int beyond = 0;
  for (const ImuSample& s : run.samples) {
    largest = std::max(largest, s.gyro_radps.cwiseAbs().maxCoeff());
    beyond += s.gyro_true_radps.cwiseAbs().maxCoeff() > p.gyro_range_radps;
  }
  CHECK(largest == Approx(p.gyro_range_radps).margin(1e-15));
  CHECK(beyond > 0);
  CHECK(run.saturated == beyond);
}

TEST_CASE("IMU dropouts remove runs of samples at about the configured rate, reproducibly", "[sim][imu]") {
  ImuParams p;
  p.dropouts_per_s = 4;
  p.dropout_s = 0.02;
  const ImuRun a = simulate_imu(p, 8, walking_camera(1), 0.0, 20.0);
  const ImuRun b = simulate_imu(p, 8, walking_camera(1), 0.0, 20.0);
  const ImuRun c = simulate_imu(p, 9, walking_camera(1), 0.0, 20.0);
  int dropped = 0, runs = 0;
  for (std::size_t k = 0; k < a.samples.size(); ++k) {
    dropped += a.samples[k].dropped;
    runs += a.samples[k].dropped && (k == 0 || !a.samples[k - 1].dropped);
    CHECK(a.samples[k].dropped == b.samples[k].dropped);
  }
  CHECK(dropped == a.dropped);
  // Expected fraction: 4/s * 20 ms / (1 + 4/s * 20 ms) ~ 7.4 %.
  CHECK(static_cast<double>(dropped) / a.samples.size() == Approx(0.074).epsilon(0.3));
  CHECK(runs > 40);
  CHECK(a.dropped != c.dropped);
}
