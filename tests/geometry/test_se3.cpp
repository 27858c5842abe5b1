// SE(3): exp and log invert each other from zero to near pi, exp's translation is Jl(phi) rho,
// apply_left is the left perturbation kept orthonormal, and the point Jacobian matches numerics.
#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/geometry/se3.h"
#include "epichead/geometry/so3.h"

using namespace epichead::geometry;

namespace {

double max_abs(const Eigen::MatrixXd& m) { return m.cwiseAbs().maxCoeff(); }

Eigen::Isometry3d some_pose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -1).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.1, -0.2, 0.9);
  return T;
}

}  // namespace

TEST_CASE("se3_log inverts se3_exp for small, ordinary and near-pi rotations") {
  for (double scale : {0.0, 1e-13, 1e-9, 1e-4, 0.3, 1.5, 3.1}) {
    Vector6d xi;
    xi << 0.2, -0.1, 0.4, 0.6, -0.48, 0.64;  // |phi| = 1 before scaling
    xi.tail<3>() *= scale;
    INFO("scale " << scale);
    CHECK(max_abs(se3_log(se3_exp(xi)) - xi) < 1e-9);
  }
}

TEST_CASE("se3_exp rotates by so3_exp(phi) and translates by the left Jacobian times rho") {
  Vector6d xi;
  xi << 0.3, 0.2, -0.1, 0.0, 0.0, M_PI / 2;  // quarter turn about z
  const Eigen::Isometry3d T = se3_exp(xi);
  CHECK(max_abs(T.linear() - Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix()) < 1e-12);
  // V = I + (1 - cos a)/a^2 W + (a - sin a)/a^3 W^2, a = pi/2.
  const double a = M_PI / 2, b = (1 - std::cos(a)) / (a * a), c = (a - std::sin(a)) / (a * a * a);
  const Eigen::Matrix3d W = skew(xi.tail<3>());
  const Eigen::Vector3d expected = (Eigen::Matrix3d::Identity() + b * W + c * W * W) * xi.head<3>();
  CHECK((T.translation() - expected).norm() < 1e-12);
}

TEST_CASE("apply_left is se3_exp(xi) * pose with an orthonormal rotation") {
  Vector6d xi;
  xi << 0.01, -0.02, 0.03, 0.2, 0.1, -0.3;
  const Eigen::Isometry3d pose = some_pose();
  const Eigen::Isometry3d got = apply_left(xi, pose);
  CHECK(max_abs(got.matrix() - (se3_exp(xi) * pose).matrix()) < 1e-14);
  CHECK(max_abs(got.linear().transpose() * got.linear() - Eigen::Matrix3d::Identity()) < 1e-15);
  CHECK(max_abs(apply_left(Vector6d::Zero(), pose).matrix() - pose.matrix()) < 1e-15);
}

TEST_CASE("left_point_jacobian is the derivative of a point under a left perturbation") {
  const Eigen::Isometry3d pose = some_pose();
  const Eigen::Vector3d p(0.05, 0.1, -0.02);
  const Eigen::Vector3d X = pose * p;
  constexpr double h = 1e-6;
  Eigen::Matrix<double, 3, 6> numeric;
  for (int k = 0; k < 6; ++k) {
    const Vector6d d = h * Vector6d::Unit(k);
    numeric.col(k) = (se3_exp(d) * X - se3_exp(-d) * X) / (2 * h);
  }
  CHECK(max_abs(left_point_jacobian(X) - numeric) < 1e-9);
}
