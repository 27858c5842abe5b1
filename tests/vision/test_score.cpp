// Scoring: known perturbations give known errors, the 5 cm / 5 deg criterion, losses, statistics,
// and the removal of the unobservable turn about a symmetry axis.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "epichead/vision/offline/score.h"

using namespace epichead::vision;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

const Camera kCamera(160, 120, Intrinsics{200, 200, 79.5, 59.5});

const CadModel& cube() {
  static const CadModel model = [] {
    auto m = load_cao(std::string(EPICHEAD_TEST_DATA) + "/seq/cube.cao");
    REQUIRE(m.has_value());
    return *m;
  }();
  return model;
}

std::vector<StampedPose> truth(int n) {
  std::vector<StampedPose> poses;
  for (int i = 0; i < n; ++i) {
    StampedPose p;
    p.frame = i;
    p.t_s = i / 30.0;
    p.cam_T_obj = Eigen::Translation3d(0.01 * i, -0.02, 0.6) *
                  Eigen::AngleAxisd(0.1 * i + 0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized());
    poses.push_back(p);
  }
  return poses;
}

// The estimate turned by angle_rad about axis_obj (in the object frame) and shifted by shift_m (camera frame).
std::vector<StampedPose> perturbed(std::vector<StampedPose> poses, const Eigen::Vector3d& axis_obj, double angle_rad,
                                   const Eigen::Vector3d& shift_m = Eigen::Vector3d::Zero()) {
  for (auto& p : poses) {
    p.cam_T_obj = p.cam_T_obj * Eigen::AngleAxisd(angle_rad, axis_obj.normalized());
    p.cam_T_obj.translation() += shift_m;
  }
  return poses;
}

// A model of single points, for reprojection errors that can be worked out by hand.
CadModel points_model(std::vector<Eigen::Vector3d> points) {
  CadModel m;
  m.vertices = std::move(points);
  return m;
}

StampedPose at(int frame, const Eigen::Vector3d& t) {
  StampedPose p;
  p.frame = frame;
  p.cam_T_obj = Eigen::Isometry3d(Eigen::Translation3d(t));
  return p;
}

}  // namespace

TEST_CASE("ground truth scored against itself succeeds everywhere with zero errors") {
  const auto gt = truth(10);
  const ScoreSummary s = score_poses(gt, gt, kCamera, cube());
  CHECK(s.frames == 10);
  CHECK(s.present == 10);
  CHECK(s.succeeded == 10);
  CHECK(s.success_rate == 1.0);
  CHECK(s.losses == 0);
  CHECK(s.rotation_deg.mean == Approx(0).margin(1e-9));
  CHECK(s.rotation_deg.p95 == Approx(0).margin(1e-9));
  CHECK(s.translation_mm.mean == 0);
  CHECK(s.reprojection_px.mean == Approx(0).margin(1e-9));
  REQUIRE(s.per_frame.size() == 10);
  CHECK(s.per_frame[4].frame == 4);
  CHECK(s.per_frame[4].present);
  CHECK(s.per_frame[4].success);
}

TEST_CASE("a 3 degree turn scores 3.000 degrees and still succeeds") {
  const auto gt = truth(5);
  const ScoreSummary s = score_poses(gt, perturbed(gt, {1, 2, -0.5}, 3 * kDeg), kCamera, cube());
  for (const auto& f : s.per_frame) {
    CHECK(f.rotation_deg == Approx(3.0).epsilon(1e-9));
    CHECK(f.translation_mm == Approx(0).margin(1e-9));
    CHECK(f.reprojection_px > 0.5);
    CHECK(f.success);
  }
  CHECK(s.rotation_deg.median == Approx(3.0).epsilon(1e-9));
  CHECK(s.success_rate == 1.0);
}

TEST_CASE("a 20 mm shift scores 20 mm and still succeeds") {
  const auto gt = truth(5);
  const ScoreSummary s = score_poses(gt, perturbed(gt, {0, 0, 1}, 0, {0.012, 0, -0.016}), kCamera, cube());
  for (const auto& f : s.per_frame) {
    CHECK(f.translation_mm == Approx(20.0).epsilon(1e-9));
    CHECK(f.rotation_deg == Approx(0).margin(1e-9));
    CHECK(f.success);
  }
  CHECK(s.losses == 0);
}

TEST_CASE("a 10 degree turn or a 6 cm shift fails the 5 cm / 5 degree criterion") {
  const auto gt = truth(4);
  const ScoreSummary turned = score_poses(gt, perturbed(gt, {0, 1, 0}, 10 * kDeg), kCamera, cube());
  CHECK(turned.succeeded == 0);
  CHECK(turned.present == 4);
  CHECK(turned.losses == 1);  // one run of four failed frames
  CHECK(turned.rotation_deg.mean == Approx(10.0).epsilon(1e-9));
  const ScoreSummary shifted = score_poses(gt, perturbed(gt, {0, 1, 0}, 0, {0, 0.06, 0}), kCamera, cube());
  CHECK(shifted.succeeded == 0);
  const ScoreSummary looser = score_poses(gt, perturbed(gt, {0, 1, 0}, 10 * kDeg), kCamera, cube(), std::nullopt,
                                          ScoreCriterion{0.05, 12.0});
  CHECK(looser.succeeded == 4);
}

TEST_CASE("a missing estimate fails its frame and counts as one loss") {
  const auto gt = truth(8);
  auto est = gt;
  est.erase(est.begin() + 3);
  const ScoreSummary s = score_poses(gt, est, kCamera, cube());
  CHECK(s.frames == 8);
  CHECK(s.present == 7);
  CHECK(s.succeeded == 7);
  CHECK(s.success_rate == Approx(7.0 / 8.0));
  CHECK(s.losses == 1);
  CHECK_FALSE(s.per_frame[3].present);
  CHECK_FALSE(s.per_frame[3].success);
  CHECK(std::isnan(s.per_frame[3].rotation_deg));
  CHECK(std::isnan(s.per_frame[3].translation_mm));
  CHECK(std::isnan(s.per_frame[3].reprojection_px));
  CHECK(s.rotation_deg.mean == Approx(0).margin(1e-9));  // over present frames only
}

TEST_CASE("losses count maximal runs of consecutive failed frames") {
  const auto gt = truth(10);
  auto est = gt;
  // Fail frames 1, 2 (a run), 5 (a run) and 9 (a run at the end); frame 2 is missing instead of wrong.
  for (int i : {1, 5, 9}) est[static_cast<std::size_t>(i)].cam_T_obj.translation().x() += 0.2;
  est.erase(est.begin() + 2);
  const ScoreSummary s = score_poses(gt, est, kCamera, cube());
  CHECK(s.succeeded == 6);
  CHECK(s.losses == 3);
  CHECK(score_poses(gt, {}, kCamera, cube()).losses == 1);
}

TEST_CASE("estimates are matched to ground truth by frame number, in any order") {
  const auto gt = truth(4);
  auto est = perturbed(gt, {1, 0, 0}, 0, {0, 0, 0.01});
  std::reverse(est.begin(), est.end());
  est.push_back(at(99, {0, 0, 1}));  // no ground truth for it: ignored
  const ScoreSummary s = score_poses(gt, est, kCamera, cube());
  CHECK(s.frames == 4);
  CHECK(s.present == 4);
  for (const auto& f : s.per_frame) CHECK(f.translation_mm == Approx(10.0));
}

TEST_CASE("mean, median and p95 are over the present frames, p95 interpolated") {
  std::vector<StampedPose> gt, est;
  const double errors_mm[] = {30, 10, 100, 40, 20};
  for (int i = 0; i < 5; ++i) {
    gt.push_back(at(i, {0, 0, 1}));
    est.push_back(at(i, {errors_mm[i] / 1000.0, 0, 1}));
  }
  gt.push_back(at(5, {0, 0, 1}));  // no estimate: not in the statistics
  const ScoreSummary s = score_poses(gt, est, kCamera, points_model({Eigen::Vector3d::Zero()}));
  CHECK(s.translation_mm.mean == Approx(40));
  CHECK(s.translation_mm.median == Approx(30));
  CHECK(s.translation_mm.p95 == Approx(88));  // 40 + 0.8 (100 - 40)
  CHECK(s.succeeded == 4);                      // 100 mm and the missing frame fail
}

TEST_CASE("reprojection error is the mean pixel distance of the projected model points") {
  // A point at the origin 1 m ahead, moved 1 cm sideways: 200 px/m * 0.01 = 2 px.
  const std::vector<StampedPose> gt{at(0, {0, 0, 1})}, est{at(0, {0.01, 0, 1})};
  CHECK(score_poses(gt, est, kCamera, points_model({Eigen::Vector3d::Zero()})).per_frame[0].reprojection_px ==
        Approx(2.0));
  // Points at 1 m and 2 m: 2 px and 1 px.
  CHECK(score_poses(gt, est, kCamera, points_model({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1)}))
            .per_frame[0].reprojection_px == Approx(1.5));
  // A point behind the camera in the poses is left out.
  CHECK(score_poses(gt, est, kCamera, points_model({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, -3)}))
            .per_frame[0].reprojection_px == Approx(2.0));
  // A point in front but outside the image at the true pose is left out too.
  CHECK(score_poses(gt, est, kCamera, points_model({Eigen::Vector3d::Zero(), Eigen::Vector3d(5, 0, 0.01)}))
            .per_frame[0].reprojection_px == Approx(2.0));
  // No usable point at all: NaN, and the statistics skip it.
  const ScoreSummary none = score_poses(gt, est, kCamera, points_model({Eigen::Vector3d(0, 0, -3)}));
  CHECK(std::isnan(none.per_frame[0].reprojection_px));
  CHECK(none.per_frame[0].success);
}

TEST_CASE("a model without vertices is reprojected through its circle centres and cylinder axis points") {
  CadModel m;
  m.circles.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 0.05});
  const std::vector<StampedPose> gt{at(0, {0, 0, 1})}, est{at(0, {0.01, 0, 1})};
  CHECK(score_poses(gt, est, kCamera, m).per_frame[0].reprojection_px == Approx(2.0));
  m.cylinders.push_back({Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, 1), 0.02});  // both ends 2 m ahead: 1 px
  CHECK(score_poses(gt, est, kCamera, m).per_frame[0].reprojection_px == Approx((2.0 + 1.0 + 1.0) / 3.0));
}

TEST_CASE("a symmetry axis removes the turn about it and not about another axis") {
  const auto gt = truth(6);
  const auto turned = perturbed(gt, {0, 0, 1}, 40 * kDeg);
  const ScoreSummary plain = score_poses(gt, turned, kCamera, cube());
  CHECK(plain.rotation_deg.mean == Approx(40).epsilon(1e-9));
  CHECK(plain.succeeded == 0);

  const ScoreSummary about_z = score_poses(gt, turned, kCamera, cube(), Eigen::Vector3d(0, 0, 2));  // any length
  CHECK(about_z.rotation_deg.mean == Approx(0).margin(1e-9));
  CHECK(about_z.reprojection_px.mean == Approx(0).margin(1e-9));  // the turned pose is the one reprojected
  CHECK(about_z.succeeded == 6);

  const ScoreSummary about_x = score_poses(gt, turned, kCamera, cube(), Eigen::Vector3d(1, 0, 0));
  CHECK(about_x.rotation_deg.mean == Approx(40).epsilon(1e-9));
  CHECK(about_x.succeeded == 0);

  // A turn about another axis survives the removal of the turn about the symmetry axis.
  auto both = gt;
  for (auto& p : both)
    p.cam_T_obj = p.cam_T_obj * Eigen::AngleAxisd(3 * kDeg, Eigen::Vector3d::UnitX()) *
                  Eigen::AngleAxisd(70 * kDeg, Eigen::Vector3d::UnitZ());
  const ScoreSummary mixed = score_poses(gt, both, kCamera, cube(), Eigen::Vector3d::UnitZ());
  CHECK(mixed.rotation_deg.mean == Approx(3).epsilon(1e-9));
}

TEST_CASE("the turn removed about the symmetry axis is the best one (checked by a scan)") {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -1, 0.4).normalized();
  StampedPose g = truth(1)[0];
  StampedPose e = g;
  e.cam_T_obj = g.cam_T_obj * Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 0.2, 0).normalized()) *
                Eigen::AngleAxisd(2.5, axis);
  const double scored = score_poses({g}, {e}, kCamera, cube(), axis).per_frame[0].rotation_deg;
  double best = 1e9;
  for (int i = 0; i < 36000; ++i) {
    const Eigen::Matrix3d R = g.cam_T_obj.linear().transpose() * e.cam_T_obj.linear() *
                              Eigen::AngleAxisd(i * 0.01 * kDeg, axis).toRotationMatrix();
    best = std::min(best, Eigen::AngleAxisd(R).angle() / kDeg);
  }
  CHECK(scored <= best + 1e-9);
  CHECK(scored == Approx(best).margin(1e-3));
  CHECK(scored > 1.0);  // the other turn is still there
}

TEST_CASE("no ground truth gives an empty summary and a zero axis is refused") {
  const ScoreSummary s = score_poses({}, truth(3), kCamera, cube());
  CHECK(s.frames == 0);
  CHECK(s.success_rate == 0);
  CHECK(s.losses == 0);
  CHECK(std::isnan(s.rotation_deg.mean));
  CHECK_THROWS_AS(score_poses(truth(1), truth(1), kCamera, cube(), Eigen::Vector3d::Zero()), std::invalid_argument);
}

TEST_CASE("the tight 2 cm / 2 degree criterion counts only the frames within it") {
  // Frames 0-1 are 15 mm off, 2-3 are 30 mm off, 4-5 are turned 3 degrees, frame 6 has no estimate.
  const auto gt = truth(7);
  std::vector<StampedPose> est;
  const auto near = perturbed(gt, {0, 0, 1}, 0, {0.009, 0, 0.012});   // 15 mm
  const auto far = perturbed(gt, {0, 0, 1}, 0, {0.018, -0.024, 0});   // 30 mm
  const auto turned = perturbed(gt, {1, -0.5, 0.2}, 3 * kDeg);
  est = {near[0], near[1], far[2], far[3], turned[4], turned[5]};
  const ScoreSummary s = score_poses(gt, est, kCamera, cube());
  REQUIRE(s.per_frame.size() == 7);
  CHECK(s.per_frame[0].translation_mm == Approx(15.0).epsilon(1e-9));
  CHECK(s.per_frame[2].translation_mm == Approx(30.0).epsilon(1e-9));
  CHECK(s.per_frame[4].rotation_deg == Approx(3.0).epsilon(1e-9));
  for (int i : {0, 1}) {
    CHECK(s.per_frame[i].success);
    CHECK(s.per_frame[i].success_tight);
  }
  for (int i : {2, 3, 4, 5}) {
    CHECK(s.per_frame[i].success);          // within 5 cm / 5 deg
    CHECK_FALSE(s.per_frame[i].success_tight);  // not within 2 cm / 2 deg
  }
  CHECK_FALSE(s.per_frame[6].success_tight);
  CHECK(s.succeeded == 6);
  CHECK(s.success_rate == Approx(6.0 / 7.0));
  CHECK(s.succeeded_tight == 2);
  CHECK(s.success_rate_tight == Approx(2.0 / 7.0));

  // The tight criterion is the one given: at 4 cm / 4 deg every present frame passes it.
  const ScoreSummary looser = score_poses(gt, est, kCamera, cube(), std::nullopt, ScoreCriterion{0.05, 5.0, 0.04, 4.0});
  CHECK(looser.succeeded_tight == 6);
  CHECK(looser.success_rate_tight == Approx(6.0 / 7.0));
}
