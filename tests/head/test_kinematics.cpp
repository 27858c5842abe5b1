// Pan/tilt kinematics: known poses in the simulator's convention, round trips, and the joint
// axes as the derivative of the camera orientation.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <random>

#include "epichead/head/head_kinematics.h"

using namespace epichead::head;

namespace {

constexpr double kDeg = std::numbers::pi / 180;

Eigen::Vector3d optical_axis_body(const HeadMount& m, const JointAngles& q) {
  return body_T_cam(m, q).linear().col(2);
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

}  // namespace

TEST_CASE("at zero joint angles the camera looks along body x, right is body -y, down is body -z", "[head][kinematics]") {
  const HeadMount m;
  const Eigen::Isometry3d T = body_T_cam(m, {0, 0});
  CHECK(T.linear().col(2).isApprox(Eigen::Vector3d::UnitX()));
  CHECK(T.linear().col(0).isApprox(-Eigen::Vector3d::UnitY()));
  CHECK(T.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ()));
  CHECK(T.translation().isApprox(Eigen::Vector3d(0.13, 0.0, 0.41)));
}

TEST_CASE("positive pan turns the camera left about body z, positive tilt looks down", "[head][kinematics]") {
  const HeadMount m;
  CHECK(optical_axis_body(m, {90 * kDeg, 0}).isApprox(Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d down = optical_axis_body(m, {0, 30 * kDeg});
  CHECK(down.isApprox(Eigen::Vector3d(std::cos(30 * kDeg), 0, -std::sin(30 * kDeg))));
  // The tilt axis turns with pan: tilting at pan 90 deg looks down toward body y.
  const Eigen::Vector3d d = optical_axis_body(m, {90 * kDeg, 30 * kDeg});
  CHECK(d.isApprox(Eigen::Vector3d(0, std::cos(30 * kDeg), -std::sin(30 * kDeg)), 1e-12));
  // The camera centre moves with pan about the pan axis foot and with tilt about the tilt axis.
  const Eigen::Vector3d c = body_T_cam(m, {90 * kDeg, 0}).translation();
  CHECK(c.isApprox(Eigen::Vector3d(0.10, 0.03, 0.41)));
}

TEST_CASE("the mount misalignment turns the camera about its own axes", "[head][kinematics]") {
  HeadMount m;
  m.cam_misalign_rad = {0.0, 0.01, 0.0};  // about camera y: the optical axis turns toward camera +x = body -y
  const Eigen::Vector3d d = optical_axis_body(m, {0, 0});
  CHECK(d.y() == Approx(-std::sin(0.01)));
  CHECK(tilt_R_cam(m).determinant() == Approx(1.0));
  CHECK((tilt_R_cam(m).transpose() * tilt_R_cam(m)).isIdentity(1e-12));
}

TEST_CASE("aim_joints points the optical axis at the target (round trip)", "[head][kinematics]") {
  const HeadMount m;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d target(2 + 3 * u(rng), 3 * u(rng), 0.4 + u(rng));
    const JointAngles q = aim_joints(m, target);
    const Eigen::Isometry3d T = body_T_cam(m, q);
    const Eigen::Vector3d p_cam = T.inverse() * target;
    REQUIRE(p_cam.z() > 0);
    CHECK(p_cam.head<2>().norm() / p_cam.z() < 1e-9);
  }
}

TEST_CASE("world_T_cam composes the body pose with the head", "[head][kinematics]") {
  const HeadMount m;
  Eigen::Isometry3d world_T_body = Eigen::Isometry3d::Identity();
  world_T_body.rotate(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 1).normalized()));
  world_T_body.pretranslate(Eigen::Vector3d(1, 2, 3));
  const JointAngles q{0.3, -0.2};
  CHECK(world_T_cam(world_T_body, m, q).isApprox(world_T_body * body_T_cam(m, q)));
}

TEST_CASE("joint_axes_cam is the camera's angular velocity per joint rate (finite differences)", "[head][kinematics]") {
  HeadMount m;
  m.cam_misalign_rad = {0.01, -0.02, 0.015};
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 50; ++i) {
    const JointAngles q{2.5 * u(rng), 1.0 * u(rng)};
    const Eigen::Matrix<double, 3, 2> J = joint_axes_cam(m, q);
    constexpr double h = 1e-6;
    const Eigen::Matrix3d R0 = body_T_cam(m, q).linear();
    const Eigen::Vector3d w_pan = so3_log(R0.transpose() * body_T_cam(m, {q.pan_rad + h, q.tilt_rad}).linear()) / h;
    const Eigen::Vector3d w_tilt = so3_log(R0.transpose() * body_T_cam(m, {q.pan_rad, q.tilt_rad + h}).linear()) / h;
    CHECK((J.col(0) - w_pan).norm() < 1e-5);
    CHECK((J.col(1) - w_tilt).norm() < 1e-5);
    CHECK(J.col(0).norm() == Approx(1.0));
  }
}
