// Is a covariance honest? vision_covariance.csv round trips and refuses what is not a
// covariance; the NEES of errors drawn from a known covariance follows chi-square, and a
// covariance ten times too small is caught; with a symmetry axis the turn about it is left out.
#include <catch2/catch.hpp>

#include <fstream>
#include <random>

#include "common/temp_dir.h"
#include "epichead/geometry/se3.h"
#include "epichead/vision/offline/pose_consistency.h"
#include "epichead/vision/offline/pose_covariance_csv.h"
#include "epichead/vision/offline/score.h"

using namespace epichead;
using namespace epichead::vision;
using epichead::testing::TempDir;

namespace {

const Camera kCamera(160, 120, Intrinsics{200, 200, 79.5, 59.5});

CadModel points_model() {
  CadModel m;
  m.vertices = {{0.05, 0, 0}, {0, 0.05, 0}, {0, 0, 0.05}, {-0.05, -0.05, 0}};
  return m;
}

// A correlated covariance of a few mm and mrad, as a pose estimator gives.
Eigen::Matrix<double, 6, 6> some_covariance() {
  Eigen::Matrix<double, 6, 6> A;
  A << 2, 0.5, 0, 0, 1, 0,  //
      0, 1.5, 0.3, 0, 0, 0.2,  //
      0, 0, 6, 0.4, 0, 0,  //
      0, 0, 0, 3, 0.5, 0,  //
      0, 0, 0, 0, 2, 0.1,  //
      0, 0, 0, 0, 0, 1;
  A *= 1e-3;
  return A * A.transpose();
}

struct Draw {
  std::vector<StampedPose> truth, estimates;
  std::vector<StampedCovariance> covariances;
};

// Estimates whose error twist (truth = exp(e) * estimate) is drawn from C; extra_turn_rad turns
// each estimate about axis_obj on top, as a tracker that cannot see that turn may.
Draw draw(int n, const Eigen::Matrix<double, 6, 6>& C, const Eigen::Vector3d& axis_obj = Eigen::Vector3d::UnitZ(),
          double extra_turn_rad = 0) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  const Eigen::Matrix<double, 6, 6> L = C.llt().matrixL();
  Draw d;
  for (int i = 0; i < n; ++i) {
    StampedPose g;
    g.frame = i;
    g.t_s = i / 30.0;
    g.cam_T_obj = Eigen::Translation3d(0.02, -0.01, 0.5) * Eigen::AngleAxisd(0.3 + 0.01 * i, Eigen::Vector3d(0.2, 1, 0.1).normalized());
    Eigen::Matrix<double, 6, 1> z;
    for (int k = 0; k < 6; ++k) z[k] = normal(rng);
    StampedPose e = g;
    e.cam_T_obj = geometry::se3_exp(-(L * z)) * g.cam_T_obj * Eigen::AngleAxisd(extra_turn_rad * ((i % 2) ? 1 : -1), axis_obj);
    d.truth.push_back(g);
    d.estimates.push_back(e);
    d.covariances.push_back({i, g.t_s, C});
  }
  return d;
}

void write_text(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

std::string header() {
  std::string h;
  for (const auto& c : pose_covariance_columns()) h += (h.empty() ? "" : ",") + c;
  return h + "\n";
}

std::string identity_row(int frame, const std::string& first = "1") {
  std::string r = std::to_string(frame) + ",0.5";
  for (int i = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) r += "," + (i == j ? (i == 0 ? first : std::string("1")) : std::string("0"));
  return r + "\n";
}

}  // namespace

TEST_CASE("vision_covariance.csv round trips its matrices", "[consistency]") {
  TempDir dir;
  const std::string path = (dir.path / "vision_covariance.csv").string();
  std::vector<StampedCovariance> rows{{3, 0.1, some_covariance()}, {5, 0.1666666666666667, 2 * some_covariance()}};
  REQUIRE(write_pose_covariance_csv(path, rows).has_value());
  const auto back = read_pose_covariance_csv(path);
  REQUIRE(back.has_value());
  REQUIRE(back->size() == 2);
  CHECK((*back)[1].frame == 5);
  CHECK((*back)[1].t_s == rows[1].t_s);
  CHECK((*back)[1].covariance.isApprox(rows[1].covariance, 1e-15));
  CHECK(((*back)[0].covariance - (*back)[0].covariance.transpose()).norm() == 0);
}

TEST_CASE("vision_covariance.csv that is not one is refused with the file and line", "[consistency]") {
  TempDir dir;
  const std::string path = (dir.path / "cov.csv").string();
  struct Case {
    const char* what;
    std::string text, expected;
  };
  const std::vector<Case> cases{
      {"wrong header", "frame,t_s,c_tx_tx\n0,0,1\n", "c_tx_ty"},
      {"NaN", header() + identity_row(0, "nan"), "c_tx_tx"},
      {"negative variance", header() + identity_row(0, "-1"), "positive semi-definite"},
      {"frames not increasing", header() + identity_row(2) + identity_row(2), "frames must increase"},
      {"short row", header() + "0,0.5,1,0\n", "columns"},
  };
  for (const Case& c : cases) {
    INFO(c.what);
    write_text(path, c.text);
    const auto r = read_pose_covariance_csv(path);
    REQUIRE_FALSE(r.has_value());
    CHECK_THAT(r.error(), Catch::Contains("cov.csv"));
    CHECK_THAT(r.error(), Catch::Contains(c.expected));
  }
}

TEST_CASE("errors drawn from the covariance give chi-square NEES, a covariance too small is caught", "[consistency]") {
  const Eigen::Matrix<double, 6, 6> C = some_covariance();
  const Draw d = draw(2000, C);
  const ScoreSummary summary = score_poses(d.truth, d.estimates, kCamera, points_model());
  const PoseConsistency honest = pose_consistency(summary, d.covariances);
  CHECK(honest.dof == 6);
  CHECK(honest.count == 2000);
  CHECK(honest.mean == Approx(6).margin(0.3));
  CHECK(honest.median == Approx(5.35).margin(0.35));  // chi-square 6's median
  CHECK(honest.within_95pct == Approx(0.95).margin(0.015));
  CHECK(honest.scale_for_mean == Approx(1).margin(0.05));

  std::vector<StampedCovariance> small = d.covariances;
  for (auto& c : small) c.covariance /= 10;
  const PoseConsistency over_confident = pose_consistency(summary, small);
  CHECK(over_confident.scale_for_mean == Approx(10).margin(0.5));
  CHECK(over_confident.above_97_5pct > 0.5);
}

TEST_CASE("with a symmetry axis the turn about it is left out of the NEES", "[consistency]") {
  // The covariance claims the turn about the axis to 1 mrad, the estimates are off by 0.05 rad
  // about it: with the axis the scoring removes that turn and the check uses the other 5 directions.
  const Eigen::Matrix<double, 6, 6> C = some_covariance();
  const Eigen::Vector3d axis(0, 0, 1);
  const Draw d = draw(2000, C, axis, 0.05);
  const PoseConsistency with_axis = pose_consistency(score_poses(d.truth, d.estimates, kCamera, points_model(), axis), d.covariances);
  CHECK(with_axis.dof == 5);
  CHECK(with_axis.count == 2000);
  CHECK(with_axis.mean == Approx(5).margin(0.3));
  CHECK(with_axis.within_95pct == Approx(0.95).margin(0.015));

  const PoseConsistency without = pose_consistency(score_poses(d.truth, d.estimates, kCamera, points_model()), d.covariances);
  CHECK(without.dof == 6);
  CHECK(without.mean > 100);
}

TEST_CASE("frames that failed or have no covariance do not count", "[consistency]") {
  const Draw d = draw(10, some_covariance());
  std::vector<StampedPose> estimates = d.estimates;
  estimates[0].cam_T_obj.translation().z() += 0.2;  // a wrong lock
  std::vector<StampedCovariance> covs(d.covariances.begin() + 2, d.covariances.end());
  const PoseConsistency c = pose_consistency(score_poses(d.truth, estimates, kCamera, points_model()), covs);
  CHECK(c.count == 8);
  const PoseConsistency none = pose_consistency(score_poses(d.truth, estimates, kCamera, points_model()), {});
  CHECK(none.count == 0);
  CHECK(std::isnan(none.mean));
}
