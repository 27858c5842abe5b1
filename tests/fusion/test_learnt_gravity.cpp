// The object's down learnt while vision and the IMU agree, and the check of a pose's tilt against
// the accelerometer (fusion/learnt_gravity.h): a pose tilted off is a wrong lock, a turn about
// gravity cannot be seen, a re-initialisation from a tilted pose is refused, and a long run of
// contradictions forgets the learnt down (the object was moved).
#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/fusion/learnt_gravity.h"
#include "epichead/fusion/predictor.h"
#include "epichead/geometry/so3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
using namespace epichead::fusion::testing;
namespace geometry = epichead::geometry;

namespace {

constexpr double deg = kDegRad;

// The truth's pose turned by `angle_rad` about `axis_cam` (camera frame).
Eigen::Isometry3d turned(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& axis_cam, double angle_rad) {
  Eigen::Isometry3d out = cam_T_obj;
  out.linear() = Eigen::AngleAxisd(angle_rad, axis_cam.normalized()).toRotationMatrix() * cam_T_obj.linear();
  return out;
}

// The sinusoidal truth tracked for `seconds` with exact 30 Hz poses: long enough to learn.
struct Tracked {
  Trajectory traj;
  ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 12.0, 5);
  Predictor predictor;
  std::size_t next = 0;
  double t_s = 0.2;

  explicit Tracked(double seconds, const PredictorOptions& options = {}) : predictor(*Predictor::create(options)) {
    feed_until(t_s);
    REQUIRE(predictor.add_vision(t_s, traj.at(t_s).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
    run_to(0.2 + seconds);
  }
  void feed_until(double t) {
    for (; next < imu.samples.size() && imu.samples[next].t_s <= t + 1e-9; ++next) predictor.add_imu(imu.samples[next]);
  }
  void run_to(double end_s) {
    while (t_s + 1.0 / 30 <= end_s) {
      t_s += 1.0 / 30;
      feed_until(t_s + 0.001);
      REQUIRE(predictor.add_vision(t_s, traj.at(t_s).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Applied);
    }
  }
  Eigen::Vector3d true_down_obj() const { return traj.params().gravity_dir_obj.normalized(); }  // gravity's direction
};

}  // namespace

TEST_CASE("the accelerometer's down, brought forward by the gyro over the window, is the true down while the camera turns") {
  const Trajectory traj;
  const ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 2.0, 1);
  StateHistory history(2100);
  for (const ImuSample& s : imu.samples) history.push(s, false);
  for (double t : {0.6, 1.0, 1.7}) {
    INFO("t " << t);
    const auto down = measured_down_imu(history, t, 0.4, 0.15, 0.0035, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    REQUIRE(down);
    // The truth: gravity (down) in the camera frame (the IMU's here). The trajectory accelerates a
    // little on average over 0.4 s, which is what is left.
    const TruthPoint p = traj.at(t);
    const Eigen::Vector3d truth = p.x.obj_R_cam.transpose() * p.x.gravity_obj_mps2().normalized();
    CHECK(angle_between(*down, truth) < 2.0 * deg);
    // Without the gyro's turn (a window of one sample's worth of turning) it would be worse:
    // the readings' plain mean is off by the turn inside the window.
    Eigen::Vector3d plain = Eigen::Vector3d::Zero();
    int n = 0;
    for (const ImuSample& s : imu.samples)
      if (s.t_s > t - 0.4 && s.t_s <= t) plain += s.accel_mps2, ++n;
    CHECK(angle_between(-plain / n, truth) > angle_between(*down, truth));
  }
}

TEST_CASE("no measured down inside a dropout, across one, or from too short a window") {
  const Trajectory traj;
  const ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 2.0, 1);
  StateHistory history(2000);
  for (const ImuSample& s : imu.samples)
    if (s.t_s < 1.0 || s.t_s > 1.3) history.push(s, false);  // a 0.3 s gap
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  CHECK(measured_down_imu(history, 0.9, 0.4, 0.15, 0.0035, zero, zero));
  CHECK_FALSE(measured_down_imu(history, 1.2, 0.4, 0.15, 0.0035, zero, zero));   // inside the gap
  CHECK_FALSE(measured_down_imu(history, 1.35, 0.4, 0.15, 0.0035, zero, zero));  // 0.05 s since it
  CHECK(measured_down_imu(history, 1.5, 0.4, 0.15, 0.0035, zero, zero));
  CHECK_FALSE(measured_down_imu(history, 0.1, 0.4, 0.15, 0.0035, zero, zero));   // 0.1 s of samples
}

TEST_CASE("the down is learnt after a second of agreeing poses, and a pose tilted 15 deg is a wrong lock while one turned about gravity is not") {
  Tracked run(0.5);
  // Half a second: not yet learnt (30 applied poses in a row are needed).
  CHECK_FALSE(run.predictor.learnt_down_obj());
  CHECK_FALSE(run.predictor.check_tilt(run.t_s, run.traj.at(run.t_s).x.cam_T_obj()));
  run.run_to(2.0);
  const auto down = run.predictor.learnt_down_obj();
  REQUIRE(down);
  CHECK(angle_between(*down, run.true_down_obj()) < 1.0 * deg);
  CHECK(run.predictor.status(run.t_s).gravity_learnt);

  const double t = run.t_s;
  const Eigen::Isometry3d truth = run.traj.at(t).x.cam_T_obj();
  const Eigen::Vector3d down_cam = truth.linear() * run.true_down_obj();
  const auto right = run.predictor.tilt_error_rad(t, truth);
  REQUIRE(right);
  CHECK(*right < 2.0 * deg);
  CHECK_FALSE(run.predictor.check_tilt(t, truth));
  // Tilted about an axis across gravity: seen.
  const Eigen::Vector3d across = down_cam.unitOrthogonal();
  CHECK(run.predictor.check_tilt(t, turned(truth, across, 15 * deg)));
  CHECK(run.predictor.status(t).counters.vision_against_gravity == 1);
  // A few degrees: within the measurement's noise, not a contradiction.
  CHECK_FALSE(run.predictor.check_tilt(t, turned(truth, across, 4 * deg)));
  // Turned about gravity itself: the accelerometer cannot tell.
  CHECK_FALSE(run.predictor.check_tilt(t, turned(truth, down_cam, 30 * deg)));
}

TEST_CASE("after a reset the predictor refuses to start again from a tilted pose and starts from an upright one") {
  Tracked run(2.0);
  REQUIRE(run.predictor.learnt_down_obj());
  run.predictor.reset();
  const double t = run.t_s + 1.0 / 30;
  run.feed_until(t + 0.001);
  const Eigen::Isometry3d truth = run.traj.at(t).x.cam_T_obj();
  const Eigen::Vector3d across = (truth.linear() * run.true_down_obj()).unitOrthogonal();
  CHECK(run.predictor.add_vision(t, turned(truth, across, 20 * deg), pose_cov(1e-3, 1e-3)).verdict ==
        VisionVerdict::AgainstGravity);
  CHECK_FALSE(run.predictor.status(t).initialised);
  // The learnt down survives the reset.
  CHECK(run.predictor.learnt_down_obj());
  CHECK(run.predictor.add_vision(t, truth, pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
}

TEST_CASE("right after an IMU gap, a run of gated poses does not restart the filter from a pose the accelerometer cannot check yet") {
  Tracked run(2.0);
  REQUIRE(run.predictor.learnt_down_obj());
  // A 0.3 s gap in the IMU (a bus-off): its samples never come.
  const double gap_end = run.t_s + 0.3;
  for (; run.next < run.imu.samples.size() && run.imu.samples[run.next].t_s < gap_end; ++run.next) {}
  // Poses 0.5 m off are gated, five in a row ask for a re-initialisation (reinit_after_gated).
  double t = gap_end;
  Eigen::Isometry3d off = run.traj.at(t).x.cam_T_obj();
  for (int i = 0; i < 5; ++i) {
    t += 0.005;
    run.feed_until(t + 0.001);
    off = run.traj.at(t).x.cam_T_obj();
    off.translation().x() += 0.5;
    CHECK(run.predictor.add_vision(t, off, pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Gated);
  }
  // 0.03 s after the gap: less than min_window_s (0.15 s) of accelerometer to check a tilt with.
  t = gap_end + 0.03;
  run.feed_until(t + 0.001);
  CHECK(run.predictor.add_vision(t, run.traj.at(t).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Unchecked);
  CHECK(run.predictor.status(t).counters.vision_unchecked == 1);
  // Once the window is there, an upright pose restarts it.
  t = gap_end + 0.2;
  run.feed_until(t + 0.001);
  CHECK(run.predictor.add_vision(t, run.traj.at(t).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
}

TEST_CASE("contradictions for longer than forget_after_s forget the learnt down, an agreeing pose between restarts the count") {
  PredictorOptions options;
  options.gravity_check.forget_after_s = 1.0;
  Tracked run(2.0, options);
  REQUIRE(run.predictor.learnt_down_obj());
  const auto tilted_at = [&](double t) {
    const Eigen::Isometry3d truth = run.traj.at(t).x.cam_T_obj();
    return turned(truth, (truth.linear() * run.true_down_obj()).unitOrthogonal(), 25 * deg);
  };
  double t = run.t_s;
  for (int i = 0; i < 20; ++i) {  // 0.67 s of contradictions
    t += 1.0 / 30;
    run.feed_until(t + 0.001);
    CHECK(run.predictor.check_tilt(t, tilted_at(t)));
  }
  t += 1.0 / 30;
  run.feed_until(t + 0.001);
  CHECK_FALSE(run.predictor.check_tilt(t, run.traj.at(t).x.cam_T_obj()));  // agrees: the run restarts
  for (int i = 0; i < 20; ++i) {
    t += 1.0 / 30;
    run.feed_until(t + 0.001);
    CHECK(run.predictor.check_tilt(t, tilted_at(t)));
  }
  CHECK(run.predictor.learnt_down_obj());
  for (int i = 0; i < 15; ++i) {  // past 1 s in a row
    t += 1.0 / 30;
    run.feed_until(t + 0.001);
    run.predictor.check_tilt(t, tilted_at(t));
  }
  CHECK_FALSE(run.predictor.learnt_down_obj());
  CHECK(run.predictor.status(t).counters.gravity_forgotten == 1);
  // Nothing learnt: nothing contradicts.
  CHECK_FALSE(run.predictor.check_tilt(t, tilted_at(t)));
}

TEST_CASE("gravity_check options out of range are refused") {
  PredictorOptions o;
  o.gravity_check.min_window_s = 1.0;  // longer than window_s
  CHECK_FALSE(Predictor::create(o));
  o = PredictorOptions{};
  o.gravity_check.max_tilt_error_rad = 0;
  CHECK_FALSE(Predictor::create(o));
  o = PredictorOptions{};
  o.gravity_check.learn_after_applied = 0;
  CHECK_FALSE(Predictor::create(o));
}

TEST_CASE("a told down checks poses from the first frame, and a start tilted under the limit does not teach it another") {
  // Poses all tilted by the same 8 deg in the object's frame: a wrong start the image supports
  // (under the 10 deg limit) and the IMU cannot contradict, since it moves as the truth does.
  const Trajectory traj;
  const ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 4.0, 7);
  const Eigen::Vector3d true_down = traj.params().gravity_dir_obj.normalized();
  const Eigen::Matrix3d offset = Eigen::AngleAxisd(8 * deg, true_down.unitOrthogonal()).toRotationMatrix();
  const auto tilted_start = [&](double t) {
    Eigen::Isometry3d p = traj.at(t).x.cam_T_obj();
    p.linear() = p.linear() * offset;
    return p;
  };
  auto track = [&](const PredictorOptions& options) {
    Predictor p = *Predictor::create(options);
    std::size_t next = 0;
    for (double t = 0.2; t < 3.0; t += 1.0 / 30) {
      for (; next < imu.samples.size() && imu.samples[next].t_s <= t + 0.001; ++next) p.add_imu(imu.samples[next]);
      p.add_vision(t, tilted_start(t), pose_cov(1e-3, 1e-3));
    }
    return p;
  };
  // Learnt: after 30 poses in a row the down is the tilted poses' (within the noise).
  const Predictor learnt = track({});
  REQUIRE(learnt.learnt_down_obj());
  CHECK(angle_between(*learnt.learnt_down_obj(), offset.transpose() * true_down) < 1.0 * deg);
  CHECK_FALSE(learnt.status(3.0).gravity_told);

  PredictorOptions options;
  options.gravity_check.told_down_obj = 2.5 * true_down;  // any length
  Predictor told = *Predictor::create(options);
  CHECK(told.learnt_down_obj());  // before any pose
  const Predictor after = track(options);
  REQUIRE(after.learnt_down_obj());
  CHECK(angle_between(*after.learnt_down_obj(), true_down) < 1e-9);
  CHECK(after.status(3.0).gravity_told);
  // The right pose agrees with it, the start's pose is 8 deg off it.
  const auto right = after.tilt_error_rad(2.9, traj.at(2.9).x.cam_T_obj());
  const auto wrong = after.tilt_error_rad(2.9, tilted_start(2.9));
  REQUIRE(right);
  REQUIRE(wrong);
  CHECK(*right < 1.5 * deg);
  CHECK(std::abs(*wrong - 8 * deg) < 1.5 * deg);
  // From the first frame: a pose 20 deg off is refused before the filter has ever started.
  Predictor fresh = *Predictor::create(options);
  for (const ImuSample& s : imu.samples)
    if (s.t_s <= 0.5) fresh.add_imu(s);
  const Eigen::Isometry3d truth = traj.at(0.5).x.cam_T_obj();
  const Eigen::Isometry3d tilted20 = turned(truth, (truth.linear() * true_down).unitOrthogonal(), 20 * deg);
  CHECK(fresh.add_vision(0.5, tilted20, pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::AgainstGravity);
  CHECK(fresh.add_vision(0.5, truth, pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Initialised);
}

TEST_CASE("a told down of zero length or not finite is refused") {
  PredictorOptions options;
  options.gravity_check.told_down_obj = Eigen::Vector3d::Zero();
  const auto zero = Predictor::create(options);
  REQUIRE_FALSE(zero);
  CHECK(zero.error().find("told_down_obj") != std::string::npos);
  options.gravity_check.told_down_obj = Eigen::Vector3d(0, 0, std::nan(""));
  CHECK_FALSE(Predictor::create(options));
}

TEST_CASE("a down learnt from a wrong lock is forgotten when the pose replacing the lock contradicts it, and kept when it agrees, was learnt before the lock or was told") {
  Tracked run(2.0);  // learnt after 30 poses, about 1.2 s
  REQUIRE(run.predictor.learnt_down_obj());
  const double t = run.t_s;
  const Eigen::Isometry3d truth = run.traj.at(t).x.cam_T_obj();
  const Eigen::Vector3d across = (truth.linear() * run.true_down_obj()).unitOrthogonal();
  const Eigen::Isometry3d tilted = turned(truth, across, 20 * deg);
  // The replacing pose agrees (a few degrees): the down stays.
  CHECK_FALSE(run.predictor.replace_wrong_lock(t, turned(truth, across, 4 * deg), 0.2));
  // Tilted 20 deg, but the lock began after the down was learnt: the pose is the likelier error.
  CHECK_FALSE(run.predictor.replace_wrong_lock(t, tilted, 1.5));
  CHECK(run.predictor.learnt_down_obj());
  // Tilted 20 deg from a down learnt while the lock was held: it was the lock's.
  CHECK(run.predictor.replace_wrong_lock(t, tilted, 0.2));
  CHECK_FALSE(run.predictor.learnt_down_obj());
  CHECK(run.predictor.status(t).counters.gravity_forgotten == 1);
  CHECK_FALSE(run.predictor.replace_wrong_lock(t, tilted, 0.2));  // nothing left to forget

  // A told down is the user's: kept.
  PredictorOptions told;
  told.gravity_check.told_down_obj = Tracked(0.1).true_down_obj();
  Tracked user(2.0, told);
  REQUIRE(user.predictor.learnt_down_obj());
  const Eigen::Isometry3d truth2 = user.traj.at(user.t_s).x.cam_T_obj();
  CHECK_FALSE(user.predictor.replace_wrong_lock(user.t_s, turned(truth2, (truth2.linear() * user.true_down_obj()).unitOrthogonal(), 20 * deg), 0.0));
  CHECK(user.predictor.learnt_down_obj());
}

TEST_CASE("a predictor restarted on a corrected clock goes on from the counters of the one it replaces") {
  Tracked run(1.0);
  const auto before = run.predictor.status(run.t_s).counters;
  REQUIRE(before.vision_applied > 20);
  auto restarted = *Predictor::create(PredictorOptions{});
  restarted.carry_learnt_gravity(run.predictor);
  restarted.carry_counters(run.predictor);
  CHECK(restarted.status(run.t_s).counters.vision_applied == before.vision_applied);
  CHECK(restarted.status(run.t_s).counters.imu_accepted == before.imu_accepted);
}
