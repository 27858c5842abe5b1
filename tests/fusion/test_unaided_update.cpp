// The filter without vision (fusion/unaided_update.h): its tilt is pulled toward the down the
// accelerometer measures and its position held near the last one vision verified; nothing acts
// on a reading that is not there (NaN, saturated: rejected) or while the camera accelerates.
#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "epichead/fusion/predictor.h"
#include "epichead/fusion/unaided_update.h"
#include "epichead/geometry/so3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
using namespace epichead::fusion::testing;
namespace geometry = epichead::geometry;

namespace {

constexpr double deg = kDegRad;

// A filter state looking along the object's z with the object's down along -y, its covariance
// `sigma_rad` in rotation and 1 cm in position.
struct Filter {
  NavState x;
  ErrorCovariance P = ErrorCovariance::Identity() * 1e-4;
  Eigen::Vector3d down_obj{0, -1, 0};
  explicit Filter(double sigma_rad) { P.block<3, 3>(err::theta, err::theta) = sigma_rad * sigma_rad * Eigen::Matrix3d::Identity(); }
  Eigen::Vector3d down_cam() const { return x.obj_R_cam.transpose() * down_obj; }
};

// The sinusoidal truth tracked for two seconds with exact 30 Hz poses (the down is learnt), then
// the IMU alone: `corrupt` may change each later sample (a gyro gone wrong, an acceleration).
struct Unaided {
  Trajectory traj;
  ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 8.0, 7);
  Predictor predictor;
  std::size_t next = 0;
  double t_s = 0.2;

  explicit Unaided(const PredictorOptions& options = {}) : predictor(*Predictor::create(options)) {
    feed_until(t_s, [](ImuSample&) {});
    REQUIRE(predictor.add_vision(t_s, traj.at(t_s).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
    while (t_s + 1.0 / 30 <= 2.2) {
      t_s += 1.0 / 30;
      feed_until(t_s + 0.001, [](ImuSample&) {});
      REQUIRE(predictor.add_vision(t_s, traj.at(t_s).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Applied);
    }
    REQUIRE(predictor.learnt_down_obj());
  }
  template <class Corrupt>
  void feed_until(double t, Corrupt corrupt) {
    for (; next < imu.samples.size() && imu.samples[next].t_s <= t + 1e-9; ++next) {
      ImuSample s = imu.samples[next];
      corrupt(s);
      predictor.add_imu(s);
    }
  }
  // The predicted pose's tilt against the truth's (rad).
  double tilt_error(double t) const {
    const auto p = predictor.predict(t);
    REQUIRE(p);
    const Eigen::Vector3d d = traj.params().gravity_dir_obj.normalized();
    return angle_between(p->cam_T_obj.linear() * d, traj.at(t).x.cam_T_obj().linear() * d);
  }
  // A unit direction across the down, in the camera (= IMU) frame, at the current time.
  Eigen::Vector3d across_down() const {
    return (traj.at(t_s).x.obj_R_cam.transpose() * traj.params().gravity_dir_obj).normalized().unitOrthogonal();
  }
  // Turns the gyro by rate_radps about an axis across the down for duration_s from now: the filter
  // comes out tilted by rate x duration, and its covariance does not know it.
  void tilt_by_gyro(double rate_radps, double duration_s) {
    const Eigen::Vector3d across = across_down();
    t_s += duration_s;
    feed_until(t_s, [&](ImuSample& s) { s.gyro_radps += rate_radps * across; });
  }
  PredictorCounters counters() const { return predictor.status(t_s).counters; }
};

}  // namespace

TEST_CASE("update_down: a tilt the filter is unsure of is pulled to the measured down, its turn about the down kept") {
  Filter f(0.1);  // 6 deg: e.g. after a gap
  const Eigen::Vector3d measured = f.down_cam();
  const Eigen::Vector3d across = measured.unitOrthogonal();
  f.x.obj_R_cam = f.x.obj_R_cam * geometry::so3_exp(5 * deg * across + 20 * deg * measured);  // 5 deg tilt and a turn
  const Eigen::Matrix3d before = f.x.obj_R_cam;
  const DownUpdateResult r = update_down(f.x, f.P, f.down_obj, measured, 0.05, 0.17);
  CHECK(r.applied);
  CHECK_FALSE(r.inflated);
  CHECK(r.angle_rad == Approx(5 * deg).epsilon(0.01));
  // The Kalman weighs the filter's 6 deg against the measurement's 3 deg: a fifth of the tilt is left.
  CHECK(angle_between(f.down_cam(), measured) < 1.2 * deg);
  // The turn about the down is not observed: the heading (the object's x seen from the camera,
  // projected across the down) is where it was.
  const auto heading = [&](const Eigen::Matrix3d& obj_R_cam) {
    const Eigen::Vector3d v = obj_R_cam.transpose() * Eigen::Vector3d::UnitX();
    return Eigen::Vector3d(v - v.dot(measured) * measured).normalized();
  };
  CHECK(angle_between(heading(f.x.obj_R_cam), heading(before)) < 0.5 * deg);
}

TEST_CASE("update_down: a filter sure of a tilt 15 deg off contradicts gravity and is pulled upright, one 5 deg off is only nudged") {
  Filter sure(0.001);
  const Eigen::Vector3d measured = sure.down_cam();
  const Eigen::Vector3d across = measured.unitOrthogonal();
  Filter nudged = sure;
  sure.x.obj_R_cam = sure.x.obj_R_cam * geometry::so3_exp(15 * deg * across);
  const DownUpdateResult r = update_down(sure.x, sure.P, sure.down_obj, measured, 0.05, 0.17);
  CHECK(r.inflated);
  CHECK(angle_between(sure.down_cam(), measured) < 1.0 * deg);
  // 5 deg from a filter that believes itself to 0.06 deg: below the contradiction, the Kalman
  // weighs 0.06 deg against the measurement's 3 deg and moves a fraction of a degree.
  nudged.x.obj_R_cam = nudged.x.obj_R_cam * geometry::so3_exp(5 * deg * across);
  const DownUpdateResult n = update_down(nudged.x, nudged.P, nudged.down_obj, measured, 0.05, 0.17);
  CHECK(n.applied);
  CHECK_FALSE(n.inflated);
  CHECK(angle_between(nudged.down_cam(), measured) > 4.9 * deg);
}

TEST_CASE("update_down and hold_position leave the state alone on a NaN measurement") {
  Filter f(0.1);
  const NavState x0 = f.x;
  const ErrorCovariance P0 = f.P;
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  CHECK_FALSE(update_down(f.x, f.P, f.down_obj, nan, 0.05, 0.17).applied);
  CHECK_FALSE(hold_position(f.x, f.P, nan, 0.2));
  CHECK(f.x.obj_R_cam == x0.obj_R_cam);
  CHECK(f.x.obj_p_cam == x0.obj_p_cam);
  CHECK(f.P == P0);
}

TEST_CASE("hold_position: a filter 0.5 m from where vision last saw the camera is brought back within the bound, one inside it is left") {
  Filter f(0.01);
  const Eigen::Vector3d seen(0.1, -0.2, -1.5);
  f.x.obj_p_cam = seen + Eigen::Vector3d(0.5, 0, 0);  // drifted, and sure of it (1 cm)
  CHECK(hold_position(f.x, f.P, seen, 0.2));
  CHECK((f.x.obj_p_cam - seen).norm() < 0.2);
  Filter inside(0.01);
  inside.x.obj_p_cam = seen + Eigen::Vector3d(0.05, 0, 0);
  CHECK_FALSE(hold_position(inside.x, inside.P, seen, 0.2));
  CHECK(inside.x.obj_p_cam == seen + Eigen::Vector3d(0.05, 0, 0));
}

TEST_CASE("Predictor without vision: a filter turned 14 deg off by a bad gyro is pulled upright by the accelerometer, with the updates off it stays off") {
  for (const bool enabled : {true, false}) {
    INFO("unaided updates " << (enabled ? "on" : "off"));
    PredictorOptions options;
    options.unaided.enabled = enabled;
    Unaided run(options);
    run.tilt_by_gyro(0.8, 0.3);  // 0.24 rad, ~14 deg
    CHECK(run.tilt_error(run.t_s) > 10 * deg);
    run.t_s += 1.0;
    run.feed_until(run.t_s, [](ImuSample&) {});
    if (enabled) {
      CHECK(run.tilt_error(run.t_s) < 2 * deg);
      CHECK(run.counters().unaided_down_updates >= 3);
      CHECK(run.counters().unaided_tilt_contradictions >= 1);
    } else {
      CHECK(run.tilt_error(run.t_s) > 10 * deg);
      CHECK(run.counters().unaided_down_updates == 0);
    }
  }
}

TEST_CASE("Predictor without vision: no tilt update while the camera accelerates (|f| off g) or the accelerometer gives no reading") {
  SECTION("a steady 1.5 m/s^2 along the down: the mean force is 0.85 g") {
    Unaided run;
    run.tilt_by_gyro(0.8, 0.3);
    const double tilted = run.tilt_error(run.t_s);
    const auto updates = run.counters().unaided_down_updates;  // one may come inside the bad gyro's 0.3 s
    const Eigen::Vector3d d = run.traj.params().gravity_dir_obj.normalized();
    run.t_s += 1.0;
    run.feed_until(run.t_s, [&](ImuSample& s) {
      // Specific force = acceleration - gravity: accelerating down by 1.5 m/s^2 takes that off
      // the reading's up-pointing 1 g.
      const Eigen::Vector3d down_imu = run.traj.at(s.t_s).x.obj_R_cam.transpose() * d;
      s.accel_mps2 += 1.5 * down_imu;
    });
    CHECK(run.counters().unaided_down_updates == updates);
    CHECK(run.tilt_error(run.t_s) > 0.8 * tilted);
  }
  SECTION("NaN and saturated readings are rejected, so nothing is measured") {
    Unaided run;
    run.tilt_by_gyro(0.8, 0.3);
    const auto updates = run.counters().unaided_down_updates;
    bool nan = true;
    run.t_s += 1.0;
    run.feed_until(run.t_s, [&](ImuSample& s) {
      s.accel_mps2.x() = nan ? std::numeric_limits<double>::quiet_NaN() : 2e4;  // beyond the 1e4 range
      nan = !nan;
    });
    CHECK(run.counters().imu_non_finite > 400);
    CHECK(run.counters().imu_saturated > 400);
    CHECK(run.counters().unaided_down_updates == updates);
  }
}

TEST_CASE("unaided options out of range are refused") {
  PredictorOptions o;
  o.unaided.down_sigma_rad = 0;
  CHECK_FALSE(Predictor::create(o));
  o = PredictorOptions{};
  o.unaided.position_sigma_m = std::numeric_limits<double>::quiet_NaN();
  CHECK_FALSE(Predictor::create(o));
}

TEST_CASE("floor_pose_covariance: the pose block is raised to the floor where it is smaller, kept where it is larger") {
  Filter f(0.001);  // 1 mrad, 1 cm: smaller than the floor in rotation, larger in position
  f.P(err::v, err::theta) = f.P(err::theta, err::v) = 1e-7;  // a cross-covariance, kept
  Matrix6d floor = Matrix6d::Zero();
  floor.diagonal() << 1e-4, 1e-4, 1e-4, 1e-6, 1e-6, 1e-6;  // 10 mrad, 1 mm
  floor(0, 3) = floor(3, 0) = 5e-7;
  const ErrorCovariance before = f.P;
  CHECK(floor_pose_covariance(f.P, floor));
  const Eigen::SelfAdjointEigenSolver<Matrix6d> above(f.P.topLeftCorner<6, 6>() - floor);
  CHECK(above.eigenvalues().minCoeff() > -1e-12);
  CHECK(f.P.block<3, 3>(err::p, err::p).isApprox(before.block<3, 3>(err::p, err::p), 1e-3));  // already above
  CHECK(f.P(err::v, err::theta) == before(err::v, err::theta));
  CHECK(Eigen::SelfAdjointEigenSolver<ErrorCovariance>(f.P).eigenvalues().minCoeff() > 0);
  const ErrorCovariance raised = f.P;
  CHECK_FALSE(floor_pose_covariance(f.P, floor));  // nothing left to raise
  CHECK(f.P == raised);
  CHECK_FALSE(floor_pose_covariance(f.P, Matrix6d::Constant(std::numeric_limits<double>::quiet_NaN())));
  CHECK(f.P == raised);
}

TEST_CASE("Predictor back after a gap: a pose the drifted filter gates re-initialises it at once with the biases kept, and with the unaided updates off it is gated") {
  for (const bool enabled : {true, false}) {
    INFO("unaided updates " << (enabled ? "on" : "off"));
    PredictorOptions options;
    options.unaided.enabled = enabled;
    Unaided run(options);
    // 0.45 s without vision in which the accelerometer reads 1 m/s^2 the camera does not have (a
    // burst the frames had not pinned down): the filter drifts ~0.1 m, and its covariance says a
    // few millimetres.
    const Eigen::Vector3d across = run.across_down();
    run.t_s += 0.45;
    run.feed_until(run.t_s + 0.001, [&](ImuSample& s) { s.accel_mps2 += 1.0 * across; });
    const auto drifted = run.predictor.predict(run.t_s);
    REQUIRE(drifted);
    CHECK((drifted->cam_T_obj.translation() - run.traj.at(run.t_s).x.cam_T_obj().translation()).norm() > 0.05);
    const Eigen::Isometry3d seen = run.traj.at(run.t_s).x.cam_T_obj();
    const Eigen::Vector3d bias = run.predictor.state()->accel_bias_mps2;
    const VisionResult r = run.predictor.add_vision(run.t_s, seen, pose_cov(1e-3, 1e-3));
    if (enabled) {
      CHECK(r.verdict == VisionVerdict::Initialised);
      CHECK(run.counters().resumption_resets == 1);
      CHECK((run.predictor.state()->accel_bias_mps2 - bias).norm() < 1e-9);
      const auto after = run.predictor.predict(run.t_s);
      REQUIRE(after);
      CHECK((after->cam_T_obj.translation() - seen.translation()).norm() < 0.002);
    } else {
      CHECK(r.verdict == VisionVerdict::Gated);
      CHECK(run.counters().resumption_resets == 0);
    }
  }
}
