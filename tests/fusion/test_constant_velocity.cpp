// Without IMU: the constant-twist filter predicts a constant-velocity motion exactly, ignores IMU
// samples, gates outliers and refuses poses out of order.
#include <catch2/catch.hpp>

#include "epichead/fusion/predictor.h"
#include "epichead/geometry/se3.h"
#include "epichead/geometry/so3.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

// Constant angular rate in the camera frame and constant velocity in the object frame.
struct ConstantTwist {
  Eigen::Matrix3d R0 = geometry::so3_exp(Eigen::Vector3d(0.1, -0.2, 0.3));
  Eigen::Vector3d p0{0.1, -0.05, -0.8};
  Eigen::Vector3d omega_cam{0.4, -0.9, 1.5};
  Eigen::Vector3d v_obj{0.3, -0.2, 0.1};
  Eigen::Isometry3d cam_T_obj(double t) const {
    NavState x;
    x.obj_R_cam = R0 * geometry::so3_exp(omega_cam * t);
    x.obj_p_cam = p0 + v_obj * t;
    return x.cam_T_obj();
  }
};

PredictorOptions cv_options() {
  PredictorOptions o;
  o.mode = PredictorMode::ConstantVelocity;
  return o;
}

}  // namespace

TEST_CASE("constant-velocity mode predicts a constant-velocity motion exactly") {
  const ConstantTwist motion;
  auto p = Predictor::create(cv_options());
  REQUIRE(p);
  const Matrix6d precise = pose_cov(1e-7, 1e-7);
  CHECK(p->add_vision(0.0, motion.cam_T_obj(0.0), precise).verdict == VisionVerdict::Initialised);
  // One second of exact poses: the prior (at rest) is forgotten and the twist is the true one.
  for (int i = 1; i <= 30; ++i)
    CHECK(p->add_vision(i / 30.0, motion.cam_T_obj(i / 30.0), precise).verdict == VisionVerdict::Applied);
  for (double t : {1.01, 1.05, 1.2}) {
    const auto pred = p->predict(t);
    REQUIRE(pred);
    const Vector6d e = geometry::se3_log(motion.cam_T_obj(t) * pred->cam_T_obj.inverse());
    INFO("t = " << t << " error " << e.transpose());
    CHECK(e.head<3>().norm() < 1e-6);
    CHECK(e.tail<3>().norm() < 1e-6);
  }
  CHECK(p->predict(1.2)->covariance.trace() > p->predict(1.01)->covariance.trace());
}

TEST_CASE("constant-velocity mode ignores IMU samples, refuses old poses and gates outliers") {
  const ConstantTwist motion;
  auto p = Predictor::create(cv_options());
  REQUIRE(p);
  CHECK(p->add_imu({0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 9.8)}) == ImuVerdict::Ignored);
  CHECK_FALSE(p->predict(0.0));
  const Matrix6d cov = pose_cov(0.002, 0.003);
  for (int i = 0; i <= 6; ++i) p->add_vision(i / 30.0, motion.cam_T_obj(i / 30.0), cov);
  CHECK(p->add_vision(0.1, motion.cam_T_obj(0.1), cov).verdict == VisionVerdict::OutOfOrder);
  const Eigen::Isometry3d outlier = geometry::se3_exp((Vector6d() << 0.5, 0, 0, 0, 0, 0).finished()) * motion.cam_T_obj(0.25);
  const VisionResult gated = p->add_vision(0.25, outlier, cov);
  CHECK(gated.verdict == VisionVerdict::Gated);
  CHECK(gated.mahalanobis2 > 100);
  const PredictorCounters c = p->status(0.3).counters;
  CHECK(c.imu_ignored == 1);
  CHECK(c.vision_out_of_order == 1);
  CHECK(c.vision_gated == 1);
  CHECK(c.vision_applied == 6);
  CHECK_FALSE(p->status(0.3).coasting);  // no IMU expected
}
