// Bad input and faults: every bad IMU sample is rejected and counted without touching the state,
// dropouts are reported and grow the covariance, gross vision outliers are gated, a run of gated
// poses or reset() leads to re-initialisation (a restart from a pose that overrules the filter keeps
// the motion), bad vision input and bad options are refused.
#include <catch2/catch.hpp>

#include <limits>
#include <string>

#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "running_predictor.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

constexpr double not_a_number = std::numeric_limits<double>::quiet_NaN();
constexpr double infinity = std::numeric_limits<double>::infinity();

bool same_state(const NavState& a, const NavState& b) {
  return a.obj_R_cam == b.obj_R_cam && a.obj_p_cam == b.obj_p_cam && a.obj_v_cam == b.obj_v_cam &&
         a.gyro_bias_radps == b.gyro_bias_radps && a.accel_bias_mps2 == b.accel_bias_mps2 && a.obj_R_grav == b.obj_R_grav;
}

}  // namespace

TEST_CASE("samples before the first pose are buffered, not propagated") {
  auto predictor = Predictor::create(PredictorOptions{});
  REQUIRE(predictor);
  CHECK(predictor->add_imu({0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.8)}) == ImuVerdict::Buffered);
  CHECK_FALSE(predictor->state());
  CHECK(predictor->status(0).counters.imu_buffered == 1);
  CHECK_FALSE(predictor->status(0).initialised);
}

TEST_CASE("non-finite, saturated, out-of-order and duplicate samples are rejected, counted, and leave the state alone") {
  PredictorOptions options;
  options.gyro_range_radps = 8.0;
  options.accel_range_mps2 = 40.0;
  Running r(options);
  Predictor& p = r.predictor;
  const NavState before = *p.state();
  const ImuSample last = r.imu.samples[r.next - 1];
  const double t = last.t_s + 0.001;
  const Eigen::Vector3d g = last.gyro_radps, a = last.accel_mps2;

  CHECK(p.add_imu({not_a_number, g, a}) == ImuVerdict::NonFinite);
  CHECK(p.add_imu({t, Eigen::Vector3d(not_a_number, 0, 0), a}) == ImuVerdict::NonFinite);
  CHECK(p.add_imu({t, g, Eigen::Vector3d(0, infinity, 0)}) == ImuVerdict::NonFinite);
  CHECK(p.add_imu({t, Eigen::Vector3d(0, 0, 8.0), a}) == ImuVerdict::Saturated);
  CHECK(p.add_imu({t, g, Eigen::Vector3d(-40.0, 0, 0)}) == ImuVerdict::Saturated);
  CHECK(p.add_imu({last.t_s - 0.0005, g, a}) == ImuVerdict::OutOfOrder);
  CHECK(p.add_imu({last.t_s, g, a}) == ImuVerdict::Duplicate);
  CHECK(same_state(*p.state(), before));
  CHECK(p.state_t_s() == Approx(last.t_s));

  const PredictorCounters c = p.status(t).counters;
  CHECK(c.imu_non_finite == 3);
  CHECK(c.imu_saturated == 2);
  CHECK(c.imu_out_of_order == 1);
  CHECK(c.imu_duplicate == 1);
  // The stream goes on as if nothing happened.
  r.feed_until(0.6);
  const ErrorVector e = error_between(r.traj.at(0.6).x, *p.state());
  CHECK(e.segment<3>(err::theta).norm() < 1e-3);
  CHECK(e.segment<3>(err::p).norm() < 2e-3);
}

TEST_CASE("an IMU dropout is reported as coasting, counted, and grows the covariance") {
  Running r;
  Predictor& p = r.predictor;
  const double t_last = p.state_t_s();
  CHECK_FALSE(p.status(t_last + 0.005).coasting);
  CHECK(p.status(t_last + 0.03).coasting);  // coast_after_s = 20 ms
  const Matrix6d cov_start = p.predict(t_last)->covariance;
  const Matrix6d cov_gap = p.predict(t_last + 0.06)->covariance;
  CHECK(cov_gap.trace() > 1.5 * cov_start.trace());
  // 60 ms of samples lost, then the stream resumes.
  for (; r.next < r.imu.samples.size() && r.imu.samples[r.next].t_s < t_last + 0.06; ++r.next) {}
  CHECK(p.add_imu(r.imu.samples[r.next++]) == ImuVerdict::Accepted);
  const PredictorStatus s = p.status(p.state_t_s());
  CHECK_FALSE(s.coasting);
  CHECK(s.counters.dropouts == 1);
  CHECK(s.counters.dropout_total_s == Approx(0.06).margin(0.0015));
  // The covariance after the gap is larger than that of a filter that saw every sample.
  Running full;
  full.feed_until(p.state_t_s());
  CHECK(p.covariance().diagonal().segment<3>(err::p).sum() > full.predictor.covariance().diagonal().segment<3>(err::p).sum());
  CHECK(p.covariance().diagonal().segment<3>(err::v).sum() > full.predictor.covariance().diagonal().segment<3>(err::v).sum());
}

TEST_CASE("a gross vision outlier is gated by its Mahalanobis distance and leaves the state alone") {
  Running r;
  Predictor& p = r.predictor;
  const double t = 0.49;
  const NavState before = *p.state();
  const Eigen::Isometry3d outlier = geometry::se3_exp((Vector6d() << 0.3, 0, 0, 0, 0.2, 0).finished()) * r.traj.at(t).x.cam_T_obj();
  const VisionResult gated = p.add_vision(t, outlier, pose_cov(0.003, 0.004));
  CHECK(gated.verdict == VisionVerdict::Gated);
  CHECK(gated.mahalanobis2 > p.options().gate_chi2);
  CHECK(same_state(*p.state(), before));
  CHECK(p.status(t).counters.vision_gated == 1);
  CHECK(p.status(t).gated_in_a_row == 1);
  // A good pose right after it passes the gate.
  const VisionResult good = p.add_vision(t + 0.005, r.traj.at(t + 0.005).x.cam_T_obj(), pose_cov(0.003, 0.004));
  CHECK(good.verdict == VisionVerdict::Applied);
  CHECK(good.mahalanobis2 < p.options().gate_chi2);
  CHECK(p.status(t).gated_in_a_row == 0);
  CHECK(p.status(t).last_nis == good.mahalanobis2);
}

TEST_CASE("after reinit_after_gated gated poses in a row the next pose re-initialises the filter") {
  PredictorOptions options;
  options.reinit_after_gated = 3;
  Running r(options);
  Predictor& p = r.predictor;
  // The object was moved (or the tracker locked onto something else): a consistent 0.4 m jump.
  const Eigen::Isometry3d jump = geometry::se3_exp((Vector6d() << 0.4, 0, 0, 0, 0, 0).finished());
  for (int i = 0; i < 3; ++i) {
    const double t = 0.45 + 0.01 * i;
    CHECK(p.add_vision(t, jump * r.traj.at(t).x.cam_T_obj(), pose_cov(0.003, 0.004)).verdict == VisionVerdict::Gated);
  }
  const VisionResult re = p.add_vision(0.48, jump * r.traj.at(0.48).x.cam_T_obj(), pose_cov(0.003, 0.004));
  CHECK(re.verdict == VisionVerdict::Initialised);
  CHECK(p.status(0.5).counters.reinitialisations == 1);
  const auto pred = p.predict(0.48);
  REQUIRE(pred);
  CHECK((pred->cam_T_obj.translation() - (jump * r.traj.at(0.48).x.cam_T_obj()).translation()).norm() < 0.01);
}

TEST_CASE("reset forgets the state, the next pose initialises again from the buffered samples") {
  Running r;
  Predictor& p = r.predictor;
  p.reset();
  CHECK_FALSE(p.status(0.5).initialised);
  CHECK_FALSE(p.predict(0.5));
  CHECK_FALSE(p.state());
  CHECK(p.add_imu(r.imu.samples[r.next++]) == ImuVerdict::Buffered);
  CHECK(p.add_vision(0.45, r.traj.at(0.45).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
  CHECK(p.status(0.5).counters.reinitialisations == 1);
  REQUIRE(p.state());
  CHECK(p.state_t_s() == Approx(r.imu.samples[r.next - 1].t_s));  // re-propagated to the newest sample
}

TEST_CASE("non-finite poses, non-rotations and unusable covariances are refused as BadInput") {
  Running r;
  Predictor& p = r.predictor;
  const Eigen::Isometry3d good = r.traj.at(0.45).x.cam_T_obj();
  const Matrix6d cov = pose_cov(0.003, 0.004);
  Eigen::Isometry3d nan_pose = good;
  nan_pose.translation().x() = not_a_number;
  Eigen::Isometry3d scaled = good;
  scaled.linear() *= 1.1;
  Matrix6d negative = cov;
  negative(2, 2) = -1e-6;
  Matrix6d asymmetric = cov;
  asymmetric(0, 5) = 1e-3;
  CHECK(p.add_vision(not_a_number, good, cov).verdict == VisionVerdict::BadInput);
  CHECK(p.add_vision(0.45, nan_pose, cov).verdict == VisionVerdict::BadInput);
  CHECK(p.add_vision(0.45, scaled, cov).verdict == VisionVerdict::BadInput);
  CHECK(p.add_vision(0.45, good, negative).verdict == VisionVerdict::BadInput);
  CHECK(p.add_vision(0.45, good, asymmetric).verdict == VisionVerdict::BadInput);
  CHECK(p.add_vision(0.45, good, Matrix6d::Constant(not_a_number)).verdict == VisionVerdict::BadInput);
  CHECK(p.status(0.5).counters.vision_bad_input == 6);
  CHECK(p.add_vision(0.45, good, cov).verdict == VisionVerdict::Applied);
  CHECK_FALSE(p.predict(not_a_number));
}

TEST_CASE("without accelerometer readings before the first pose, ImuAided cannot initialise gravity") {
  auto p = Predictor::create(PredictorOptions{});
  REQUIRE(p);
  const Trajectory traj;
  CHECK(p->add_vision(0.1, traj.at(0.1).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::NoImu);
  CHECK(p->status(0.1).counters.vision_no_imu == 1);
  CHECK_FALSE(p->status(0.1).initialised);
}

TEST_CASE("invalid options are refused with the field's name") {
  PredictorOptions o;
  o.imu_noise.gyro_noise_radps_rthz = -1;
  auto p = Predictor::create(o);
  REQUIRE_FALSE(p);
  CHECK(p.error().find("imu_noise") != std::string::npos);
  o = {};
  o.mount.cam_R_imu = Eigen::Matrix3d::Identity() * 2;
  REQUIRE_FALSE(Predictor::create(o));
  CHECK(Predictor::create(o).error().find("cam_R_imu") != std::string::npos);
  o = {};
  o.buffer_s = not_a_number;
  CHECK_FALSE(Predictor::create(o));
  o = {};
  o.reinit_after_gated = 0;
  CHECK_FALSE(Predictor::create(o));
}

TEST_CASE("a wild IMU stamp is rejected as a time jump, a stream that stays there restarts the filter") {
  Running r;
  Predictor& p = r.predictor;
  const ImuSample last = r.imu.samples[r.next - 1];
  const NavState before = *p.state();
  // One stamp 1000 s ahead, then the stream goes on normally: only the wild one is lost.
  CHECK(p.add_imu({last.t_s + 1000.0, last.gyro_radps, last.accel_mps2}) == ImuVerdict::TimeJump);
  CHECK(same_state(*p.state(), before));
  CHECK(p.add_imu(r.imu.samples[r.next++]) == ImuVerdict::Accepted);
  CHECK(p.status(0.5).counters.imu_time_jump == 1);
  // The device clock steps by 5000 s and stays there: after three consistent samples the stream
  // restarts and the next pose initialises again.
  CHECK(p.add_imu({5000.000, last.gyro_radps, last.accel_mps2}) == ImuVerdict::TimeJump);
  CHECK(p.add_imu({5000.001, last.gyro_radps, last.accel_mps2}) == ImuVerdict::TimeJump);
  CHECK(p.add_imu({5000.002, last.gyro_radps, last.accel_mps2}) == ImuVerdict::Buffered);
  CHECK_FALSE(p.status(5000.002).initialised);
  CHECK(p.status(5000.002).counters.imu_restarts == 1);
  CHECK(p.status(5000.002).counters.imu_time_jump == 3);
  CHECK(p.add_vision(5000.002, r.traj.at(0.45).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict ==
        VisionVerdict::Initialised);
  // A step back in time (a device reboot) is the same case.
  CHECK(p.add_imu({0.000, last.gyro_radps, last.accel_mps2}) == ImuVerdict::TimeJump);
}

TEST_CASE("a pose stamped more than buffer_s after the newest sample is refused as BadInput") {
  Running r;
  Predictor& p = r.predictor;
  CHECK(p.add_vision(p.state_t_s() + 0.6, r.traj.at(0.45).x.cam_T_obj(), pose_cov(3e-3, 4e-3)).verdict ==
        VisionVerdict::BadInput);
  CHECK(p.add_vision(1e12, r.traj.at(0.45).x.cam_T_obj(), pose_cov(3e-3, 4e-3)).verdict == VisionVerdict::BadInput);
  CHECK(p.add_imu(r.imu.samples[r.next++]) == ImuVerdict::Accepted);
}

TEST_CASE("a restart keeping the motion takes the pose and keeps the camera's velocity and gravity as the IMU measured them") {
  // The caller decided the filter's object frame was off by 8 deg (the pose it restarts from is
  // turned so): the camera's velocity and the gravity direction, in the camera frame where the IMU
  // measures them, carry over, re-expressed in the new object frame; a plain reset starts the
  // velocity at zero with the default 0.5 m/s 1-sigma.
  const Eigen::Isometry3d turned_obj(Eigen::AngleAxisd(8 * kDegRad, Eigen::Vector3d(1, 0.3, 0).normalized()));
  const double t = 0.5;  // the newest sample's time: the carried motion is the newest state's
  Running r;
  Predictor& p = r.predictor;
  REQUIRE(p.state());
  const NavState old = *p.state();
  const Eigen::Matrix3d old_cam_R_obj = old.obj_R_cam.transpose();
  const Eigen::Isometry3d pose = r.traj.at(t).x.cam_T_obj() * turned_obj;
  const VisionResult re = p.restart_keeping_motion(t, pose, pose_cov(1e-3, 1e-3));
  CHECK(re.verdict == VisionVerdict::Initialised);
  REQUIRE(p.state());
  const NavState now = *p.state();
  CHECK((now.cam_T_obj().matrix() - pose.matrix()).norm() < 1e-9);
  const Eigen::Matrix3d cam_R_obj = now.obj_R_cam.transpose();
  CHECK(old.obj_v_cam.norm() > 0.05);  // the trajectory moves
  CHECK((cam_R_obj * now.obj_v_cam - old_cam_R_obj * old.obj_v_cam).norm() < 1e-9);
  CHECK((cam_R_obj * now.gravity_obj_mps2() - old_cam_R_obj * old.gravity_obj_mps2()).norm() < 1e-9);
  CHECK(now.gyro_bias_radps == old.gyro_bias_radps);
  CHECK(now.accel_bias_mps2 == old.accel_bias_mps2);
  const double velocity_sigma = std::sqrt(p.covariance().diagonal().segment<3>(err::v).maxCoeff());
  CHECK(velocity_sigma < 0.1);

  Running plain;
  plain.predictor.reset();
  CHECK(plain.predictor.add_vision(t, pose, pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
  CHECK(plain.predictor.state()->obj_v_cam.norm() == 0);
  CHECK(std::sqrt(plain.predictor.covariance()(err::v, err::v)) == Approx(0.5));
}
