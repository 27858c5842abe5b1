// SO(3): exp and log invert each other from zero to near pi, exp is Eigen's angle-axis rotation,
// and the left and right Jacobians (and their inverses) match numeric derivatives; rotation_between
// turns one direction into another.
#include <catch2/catch.hpp>

#include <cmath>
#include <utility>

#include <Eigen/Geometry>

#include "epichead/geometry/so3.h"

using namespace epichead::geometry;

namespace {

const Eigen::Vector3d kAxis = Eigen::Vector3d(0.6, -0.48, 0.64);  // unit length
const double kAngles[] = {0.0, 1e-13, 1e-9, 1e-7, 1e-4, 0.3, 1.5, 3.1, M_PI - 1e-6};

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

}  // namespace

TEST_CASE("skew(v) * w is v x w") {
  const Eigen::Vector3d v(0.3, -1.2, 2.0), w(-0.7, 0.1, 0.4);
  CHECK(max_abs(skew(v) * w - v.cross(w)) < 1e-15);
  CHECK(max_abs(skew(v) + skew(v).transpose()) == 0.0);
}

TEST_CASE("so3_exp is the rotation of angle |phi| about phi, at every angle scale") {
  for (double angle : kAngles) {
    INFO("angle " << angle);
    const Eigen::Matrix3d R = so3_exp(angle * kAxis);
    CHECK(max_abs(R - Eigen::AngleAxisd(angle, kAxis).toRotationMatrix()) < 1e-14);
    CHECK(max_abs(R.transpose() * R - Eigen::Matrix3d::Identity()) < 1e-14);
  }
}

TEST_CASE("so3_log inverts so3_exp for small, ordinary and near-pi angles") {
  for (double angle : kAngles) {
    INFO("angle " << angle);
    const Eigen::Vector3d phi = angle * kAxis;
    const Eigen::Vector3d back = so3_log(so3_exp(phi));
    CHECK(max_abs(back - phi) < 1e-9 * std::max(1.0, angle));
    if (angle > 0 && angle < 1e-3) CHECK((back - phi).norm() < 1e-6 * angle);  // relative at small angles
  }
}

TEST_CASE("so3_log returns an angle in [0, pi] for a turn beyond pi") {
  const Eigen::Vector3d phi = so3_log(so3_exp(4.0 * kAxis));
  CHECK(phi.norm() <= M_PI);
  CHECK(max_abs(so3_exp(phi) - so3_exp(4.0 * kAxis)) < 1e-12);
}

TEST_CASE("the left and right Jacobians match numeric derivatives of exp") {
  constexpr double h = 1e-6;
  for (double angle : {0.0, 1e-9, 1e-4, 0.3, 1.5, 3.0}) {
    INFO("angle " << angle);
    const Eigen::Vector3d phi = angle * kAxis;
    const Eigen::Matrix3d R = so3_exp(phi);
    Eigen::Matrix3d Jl_num, Jr_num;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = h * Eigen::Vector3d::Unit(k);
      // exp(phi + d) = exp(Jl d) exp(phi) = exp(phi) exp(Jr d), to first order in d.
      Jl_num.col(k) = (so3_log(so3_exp(phi + d) * R.transpose()) - so3_log(so3_exp(phi - d) * R.transpose())) / (2 * h);
      Jr_num.col(k) = (so3_log(R.transpose() * so3_exp(phi + d)) - so3_log(R.transpose() * so3_exp(phi - d))) / (2 * h);
    }
    CHECK(max_abs(so3_left_jacobian(phi) - Jl_num) < 1e-8);
    CHECK(max_abs(so3_right_jacobian(phi) - Jr_num) < 1e-8);
    // 1e-8, not rounding: Jl's closed form loses its W coefficient where 1 - cos(a) cancels
    // (a in 1e-12..1e-5, kept bit-identical to the pose solver's old apply_left), and Jl^-1's
    // closed form above its 1e-6 series threshold does the same (kept from fusion's se3_log).
    CHECK(max_abs(so3_left_jacobian_inverse(phi) * so3_left_jacobian(phi) - Eigen::Matrix3d::Identity()) < 1e-8);
    CHECK(max_abs(so3_right_jacobian_inverse(phi) * so3_right_jacobian(phi) - Eigen::Matrix3d::Identity()) < 1e-8);
  }
}

TEST_CASE("rotation_between turns one direction into another, opposite and equal ones too") {
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), z = Eigen::Vector3d::UnitZ();
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> pairs[] = {
      {z, Eigen::Vector3d(1, 2, 3)}, {3 * x, x}, {x, -2 * x}, {z, Eigen::Vector3d(1e-13, 0, -1)}, {Eigen::Vector3d(0, 0, -1), z}};
  for (const auto& [from, to] : pairs) {
    INFO("from " << from.transpose() << " to " << to.transpose());
    const Eigen::Matrix3d R = rotation_between(from, to);
    CHECK(max_abs(R * R.transpose() - Eigen::Matrix3d::Identity()) < 1e-12);
    CHECK(R.determinant() == Approx(1.0).margin(1e-12));
    CHECK(max_abs(R * from.normalized() - to.normalized()) < 1e-12);
  }
  // The smallest such rotation: its angle is the one between the directions.
  const Eigen::Vector3d to(1, 2, 3);
  CHECK(so3_log(rotation_between(z, to)).norm() == Approx(std::acos(to.normalized().z())).margin(1e-12));
}
