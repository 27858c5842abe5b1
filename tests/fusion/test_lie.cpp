// The SE(3) maps: exp and log invert each other (also near zero and near pi), and exp is the one
// vision::apply_left uses (rotation by Rodrigues, translation V(phi) * rho).
#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/fusion/lie.h"

using namespace epichead::fusion;

TEST_CASE("se3_log inverts se3_exp for small, ordinary and near-pi rotations") {
  for (double scale : {0.0, 1e-9, 1e-4, 0.3, 1.5, 3.1}) {
    Vector6d xi;
    xi << 0.2, -0.1, 0.4, 0.6, -0.48, 0.64;  // |phi| = 1 before scaling
    xi.tail<3>() *= scale;
    const Vector6d back = se3_log(se3_exp(xi));
    INFO("scale " << scale);
    CHECK((back - xi).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("se3_exp has the translation V(phi) rho of vision::apply_left") {
  Vector6d xi;
  xi << 0.3, 0.2, -0.1, 0.0, 0.0, M_PI / 2;  // quarter turn about z
  const Eigen::Isometry3d T = se3_exp(xi);
  CHECK(T.linear().isApprox(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix(), 1e-12));
  // V = I + (1 - cos a)/a^2 W + (a - sin a)/a^3 W^2, a = pi/2.
  const double a = M_PI / 2, b = (1 - std::cos(a)) / (a * a), c = (a - std::sin(a)) / (a * a * a);
  const Eigen::Matrix3d W = skew(xi.tail<3>());
  const Eigen::Vector3d expected = (Eigen::Matrix3d::Identity() + b * W + c * W * W) * xi.head<3>();
  CHECK((T.translation() - expected).norm() < 1e-12);
  CHECK(so3_log(so3_exp(Eigen::Vector3d(0, 0, 1e-8))).isApprox(Eigen::Vector3d(0, 0, 1e-8), 1e-6));
}
