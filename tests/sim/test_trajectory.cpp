#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "epichead/sim/head_mount.h"
#include "epichead/sim/trajectory.h"

using namespace epichead::sim;

namespace {

constexpr double deg = std::numbers::pi / 180.0;

// Numerical derivatives of the pose, to check the analytic rates (not used by the simulator).
Eigen::Vector3d numeric_omega(const std::function<Kinematics(double)>& f, double t, double h = 1e-5) {
  const Eigen::Matrix3d Ra = f(t - h).pose.linear(), Rb = f(t + h).pose.linear();
  const Eigen::AngleAxisd d(Rb * Ra.transpose());
  return d.axis() * d.angle() / (2 * h);
}

Kinematics walking_cam(const Trajectory& body, const HeadMount& mount, double t) {
  HeadAngles head;
  head.pan_rad = 0.3;
  head.tilt_rad = 0.2;
  head.pan_rate_radps = 0.5;  // moving joints exercise the Coriolis terms of compose()
  head.tilt_rate_radps = -0.4;
  head.pan_accel_radps2 = 0.7;
  return compose(body.at(t), body_T_cam(mount, head));
}

}  // namespace

TEST_CASE("composed kinematics match numerical derivatives of the composed pose", "[sim][trajectory]") {
  WalkingParams p;
  p.jerk = 1.5;
  const Trajectory body = Trajectory::walking(p);
  HeadMount mount;
  mount.cam_misalign_rad = {0.01, -0.02, 0.005};
  // The head moves with constant rate/accel only at one instant, so compare at that instant using
  // the quadratic joint motion around it.
  for (double t : {0.35, 0.41, 1.8, 3.05, 7.2}) {
    auto f = [&](double tt) {
      const double dt = tt - t;
      HeadAngles h;
      h.pan_rad = 0.3 + 0.5 * dt + 0.35 * dt * dt;
      h.pan_rate_radps = 0.5 + 0.7 * dt;
      h.pan_accel_radps2 = 0.7;
      h.tilt_rad = 0.2 - 0.4 * dt;
      h.tilt_rate_radps = -0.4;
      return compose(body.at(tt), body_T_cam(mount, h));
    };
    const Kinematics k = walking_cam(body, mount, t);
    const double h = 1e-4;
    const Eigen::Vector3d p0 = f(t - h).pose.translation(), p1 = k.pose.translation(), p2 = f(t + h).pose.translation();
    CHECK((k.vel_mps - (p2 - p0) / (2 * h)).norm() < 1e-5);  // difference error O(h^2)
    CHECK((k.accel_mps2 - (p2 - 2 * p1 + p0) / (h * h)).norm() < 1e-3);
    CHECK((k.omega_radps - numeric_omega(f, t)).norm() < 1e-7);
    const Eigen::Vector3d alpha_num = (f(t + h).omega_radps - f(t - h).omega_radps) / (2 * h);
    CHECK((k.alpha_radps2 - alpha_num).norm() < 1e-3);
  }
}

TEST_CASE("walking robot at jerk 1 has one 30-80 deg/s burst per step and advances about 3 cm/s",
          "[sim][trajectory]") {
  WalkingParams p;
  p.seed = 7;
  const Trajectory body = Trajectory::walking(p);
  const int steps = 20;
  double lowest = 1e9, highest = 0;
  for (int k = 0; k < steps; ++k) {
    const double t0 = p.first_step_s + k * p.step_period_s;
    const double peak = peak_angular_rate_degps(body, t0, t0 + p.step_period_s, 2e-4);
    lowest = std::min(lowest, peak);
    highest = std::max(highest, peak);
    // Between bursts the body does not turn.
    CHECK(body.at(t0 + p.burst_s + 0.05).omega_radps.norm() == 0.0);
  }
  CHECK(lowest >= 29.9);
  CHECK(highest <= 80.1);
  CHECK(highest - lowest > 20);  // the bursts vary from step to step
  const double duration = steps * p.step_period_s;
  const double advance = (body.at(duration).pose.translation() - body.at(0).pose.translation()).norm();
  CHECK(advance / duration == Approx(0.03).epsilon(0.05));
  // The body dips by about bob_m at every step.
  double lowest_z = 0;
  for (double t = 0; t < duration; t += 1e-3) lowest_z = std::min(lowest_z, body.at(t).pose.translation().z());
  CHECK(lowest_z == Approx(-p.bob_m).epsilon(0.02));
}

TEST_CASE("jerk scales the walking robot's bursts and dip", "[sim][trajectory]") {
  WalkingParams p;
  const Trajectory one = Trajectory::walking(p);
  p.jerk = 2.5;
  const Trajectory more = Trajectory::walking(p);
  CHECK(peak_angular_rate_degps(more, 0, 10) == Approx(2.5 * peak_angular_rate_degps(one, 0, 10)).epsilon(1e-3));
  const double t_dip = p.first_step_s + p.bob_s / 2;
  CHECK(more.at(t_dip).pose.translation().z() == Approx(2.5 * one.at(t_dip).pose.translation().z()));
}

TEST_CASE("jerk scales the hand-held camera's shakes, not its sway", "[sim][trajectory]") {
  HandheldParams p;
  p.sway_deg = 0;  // no sway: the peak rate is the shake's alone
  p.shakes.push_back({1.0, 0.3, Eigen::Vector3d::UnitZ(), 100 * deg});
  const Trajectory one = Trajectory::handheld(p);
  p.jerk = 2.0;
  const Trajectory more = Trajectory::handheld(p);
  CHECK(peak_angular_rate_degps(one, 0, 3, 1e-4) == Approx(100).epsilon(2e-3));
  CHECK(peak_angular_rate_degps(more, 0, 3, 1e-4) == Approx(200).epsilon(2e-3));
  // Before the shake the two are the same motion.
  CHECK(one.at(0.5).pose.isApprox(more.at(0.5).pose, 1e-12));
}

TEST_CASE("wheeled robot drives its distance smoothly and turns with the given peak rate", "[sim][trajectory]") {
  WheeledParams p;
  p.start_world = {3, 0.5, 0};
  p.distance_m = 2.0;
  p.drive_start_s = 0.5;
  p.drive_duration_s = 8;
  p.turn = {4.0, 20 * deg, 90 * deg};
  const Trajectory body = Trajectory::wheeled(p);
  CHECK((body.at(9).pose.translation() - p.start_world).norm() == Approx(2.0).epsilon(1e-9));
  CHECK(peak_angular_rate_degps(body, 0, 9, 1e-4) == Approx(90).epsilon(1e-3));
  const Eigen::Matrix3d R = body.at(9).pose.linear();
  CHECK(std::atan2(R(1, 0), R(0, 0)) == Approx(p.heading_rad + 20 * deg - 2 * std::numbers::pi).margin(1e-9));
  // C2: acceleration changes by at most a small amount per millisecond, also where pieces join.
  double worst = 0;
  for (double t = 0; t < 9; t += 1e-3) worst = std::max(worst, (body.at(t + 1e-3).accel_mps2 - body.at(t).accel_mps2).norm());
  CHECK(worst < 0.01);
}

TEST_CASE("hand-held sway is reproducible for a seed and differs between seeds", "[sim][trajectory]") {
  HandheldParams p;
  p.seed = 3;
  const Kinematics a = Trajectory::handheld(p).at(2.3), b = Trajectory::handheld(p).at(2.3);
  CHECK(a.pose.isApprox(b.pose, 0));
  p.seed = 4;
  const Kinematics c = Trajectory::handheld(p).at(2.3);
  CHECK(!a.pose.isApprox(c.pose, 1e-6));
  // The sway stays within a few amplitudes of the viewpoint.
  CHECK((a.pose.translation() - p.start_world).norm() < 3 * p.sway_m);
}

TEST_CASE("head aimed at a target puts it on the optical axis", "[sim][head]") {
  HeadMount mount;
  mount.cam_offset_tilt = Eigen::Vector3d::Zero();  // aim_at ignores the camera offset
  Eigen::Isometry3d world_T_body = Eigen::Isometry3d::Identity();
  world_T_body.translation() = Eigen::Vector3d(1.5, 0.4, 0.0);
  world_T_body.linear() = Eigen::AngleAxisd(2.8, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d target(0, 0, 0.2);
  const HeadAngles a = aim_at(mount, world_T_body, target);
  const Eigen::Isometry3d world_T_cam = world_T_body * body_T_cam(mount, a).pose;
  const Eigen::Vector3d p_cam = world_T_cam.inverse() * target;
  CHECK(p_cam.z() > 1.0);
  CHECK(std::abs(p_cam.x() / p_cam.z()) < 1e-12);
  CHECK(std::abs(p_cam.y() / p_cam.z()) < 1e-12);
  // Camera y points down in the world when the head is level (no roll from the kinematics).
  CHECK(world_T_cam.linear().col(1).z() < -0.9);
}
