// Who is wrong when vision and the filter disagree (fusion/vision_arbiter.h): a well-supported pose
// from the second opinion, three well-supported gated poses in a row, or gated poses that agree
// with each other restart the filter from vision, keeping its motion; weakly supported or
// scattered gated poses leave the filter alone.
#include <catch2/catch.hpp>

#include <random>

#include "epichead/fusion/vision_arbiter.h"
#include "epichead/geometry/se3.h"
#include "running_predictor.h"
#include "truth_helpers.h"

using namespace epichead::fusion;
namespace geometry = epichead::geometry;
using namespace epichead::fusion::testing;

namespace {

constexpr PoseSupport kStrong{.strong = true, .from_fallback = false};
constexpr PoseSupport kWeak{.strong = false, .from_fallback = false};

// Frames at 30 Hz after the fixture's last pose (0.4 s); the IMU is fed up to just past each.
double frame_t(int k) { return 0.4 + (k + 1) / 30.0; }

// Gated poses alone never re-initialise the filter here: only the arbiter restarts it.
PredictorOptions no_reinit() {
  PredictorOptions o;
  o.reinit_after_gated = 1000;
  return o;
}

// The filter is off by this (or the tracker found another object there): 0.2 m and 0.15 rad.
Eigen::Isometry3d offset() { return geometry::se3_exp((Vector6d() << 0.2, 0, 0, 0, 0.15, 0).finished()); }

double translation_error_m(Predictor& p, double t_s, const Eigen::Isometry3d& expected) {
  const auto pred = p.predict(t_s);
  REQUIRE(pred);
  return (pred->cam_T_obj.translation() - expected.translation()).norm();
}

}  // namespace

TEST_CASE("vision arbiter: a well-supported pose found from the second opinion restarts the filter at once") {
  Running r(no_reinit());
  VisionArbiter arbiter(r.predictor.options().gate_chi2);
  const double t = frame_t(0);
  r.feed_until(t + 0.001);
  const Eigen::Isometry3d moved = offset() * r.traj.at(t).x.cam_T_obj();
  // Weakly supported: the filter keeps its own estimate.
  const ArbitratedVision weak = arbiter.add_vision(r.predictor, t, moved, pose_cov(0.003, 0.004), {.strong = false, .from_fallback = true});
  CHECK(weak.result.verdict == VisionVerdict::Gated);
  CHECK(weak.restart == RestartReason::None);
  const double t1 = frame_t(1);
  r.feed_until(t1 + 0.001);
  const Eigen::Isometry3d moved1 = offset() * r.traj.at(t1).x.cam_T_obj();
  const ArbitratedVision strong = arbiter.add_vision(r.predictor, t1, moved1, pose_cov(0.003, 0.004), {.strong = true, .from_fallback = true});
  CHECK(strong.result.verdict == VisionVerdict::Gated);
  CHECK(strong.restart == RestartReason::Fallback);
  CHECK(std::string(to_string(strong.restart)) == "fallback");
  CHECK(strong.after_restart.verdict == VisionVerdict::Initialised);
  CHECK(&strong.final() == &strong.after_restart);
  CHECK(translation_error_m(r.predictor, t1, moved1) < 1e-3);
  CHECK(arbiter.counters().fallback == 1);
  CHECK(arbiter.counters().supported_gated + arbiter.counters().agreeing_gated == 0);
}

TEST_CASE("vision arbiter: three well-supported gated poses in a row restart the filter, weak ones do not") {
  Running r(no_reinit());
  VisionArbiter arbiter(r.predictor.options().gate_chi2);
  std::mt19937_64 rng(7);
  // Weakly supported poses that scatter far from the filter: gated, and never a restart.
  for (int k = 0; k < 6; ++k) {
    const double t = frame_t(k);
    r.feed_until(t + 0.001);
    const Vector6d scatter = (Vector6d() << 0.3 * (k % 2 ? 1 : -1), 0.1 * k, 0, 0, 0.2 * (k % 3) - 0.2, 0.1).finished();
    const ArbitratedVision a = arbiter.add_vision(r.predictor, t, geometry::se3_exp(scatter) * r.traj.at(t).x.cam_T_obj(),
                                                  pose_cov(0.003, 0.004), kWeak);
    CHECK(a.result.verdict == VisionVerdict::Gated);
    CHECK(a.restart == RestartReason::None);
  }
  // The filter still holds the truth.
  CHECK(translation_error_m(r.predictor, frame_t(5), r.traj.at(frame_t(5)).x.cam_T_obj()) < 0.01);
  // Well supported: the third in a row restarts it (scattered too, so agreement is not what fires).
  RestartReason last = RestartReason::None;
  Eigen::Isometry3d moved;
  for (int k = 6; k < 9; ++k) {
    const double t = frame_t(k);
    r.feed_until(t + 0.001);
    const Vector6d scatter = (Vector6d() << 0.25 + 0.2 * (k - 6), 0, 0, 0, 0, 0.3 * (k - 7)).finished();
    moved = geometry::se3_exp(scatter) * r.traj.at(t).x.cam_T_obj();
    const ArbitratedVision a = arbiter.add_vision(r.predictor, t, moved, pose_cov(0.003, 0.004), kStrong);
    CHECK(a.result.verdict == VisionVerdict::Gated);
    last = a.restart;
    if (k < 8) CHECK(a.restart == RestartReason::None);
  }
  CHECK(last == RestartReason::SupportedGated);
  CHECK(translation_error_m(r.predictor, frame_t(8), moved) < 1e-3);
  CHECK(arbiter.counters().supported_gated == 1);
  CHECK(arbiter.counters().agreeing_gated == 0);
}

TEST_CASE("vision arbiter: gated poses that agree restart the filter with applied ones between them, and clear() forgets them") {
  for (const bool cleared : {false, true}) {
    Running r(no_reinit());
    VisionArbiter arbiter(r.predictor.options().gate_chi2);
    // Every other frame the tracker finds what the filter predicts (applied), in between the
    // same object 0.2 m and 0.15 rad away (gated, weakly supported): a filter on a wrong lock.
    RestartReason restart = RestartReason::None;
    int gated = 0;
    for (int k = 0; k < 6 && restart == RestartReason::None; ++k) {
      const double t = frame_t(k);
      r.feed_until(t + 0.001);
      const Eigen::Isometry3d truth = r.traj.at(t).x.cam_T_obj();
      if (k % 2 == 0) {
        CHECK(arbiter.add_vision(r.predictor, t, truth, pose_cov(0.003, 0.004), kWeak).result.verdict == VisionVerdict::Applied);
        continue;
      }
      if (cleared && gated == 2) arbiter.clear();  // e.g. the filter was reset after a loss
      const ArbitratedVision a = arbiter.add_vision(r.predictor, t, offset() * truth, pose_cov(0.003, 0.004), kWeak);
      CHECK(a.result.verdict == VisionVerdict::Gated);
      ++gated;
      restart = a.restart;
    }
    if (cleared) {
      CHECK(restart == RestartReason::None);
      CHECK(arbiter.counters().agreeing_gated == 0);
    } else {
      CHECK(gated == 3);
      CHECK(restart == RestartReason::AgreeingGated);
      CHECK(arbiter.counters().agreeing_gated == 1);
      const double t = frame_t(5);
      CHECK(translation_error_m(r.predictor, t, offset() * r.traj.at(t).x.cam_T_obj()) < 1e-3);
    }
  }
}
