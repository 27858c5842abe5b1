#pragma once
// A predictor that has been tracking for a while, for the tests that then disturb it (faults,
// the vision arbiter): exact IMU readings, exact poses at 30 Hz.
#include <catch2/catch.hpp>

#include "epichead/fusion/predictor.h"
#include "truth_helpers.h"

namespace epichead::fusion::testing {

// A predictor initialised at 0.2 s, run on exact readings to 0.5 s with 30 Hz poses to 0.4 s.
struct Running {
  Trajectory traj;
  ImuRun imu = simulate_imu(traj, ImuErrors{}, 0.0, 1.0, 3);
  Predictor predictor;
  std::size_t next = 0;  // index of the next sample to give

  explicit Running(const PredictorOptions& options = {}) : predictor(*Predictor::create(options)) {
    feed_until(0.2);
    REQUIRE(predictor.add_vision(0.2, traj.at(0.2).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict ==
            VisionVerdict::Initialised);
    for (int i = 1; i <= 6; ++i) {  // the last pose at 0.4 s: the tests add later ones
      const double t = 0.2 + i / 30.0;
      feed_until(t + 0.001);
      REQUIRE(predictor.add_vision(t, traj.at(t).x.cam_T_obj(), pose_cov(1e-3, 1e-3)).verdict == VisionVerdict::Applied);
    }
    feed_until(0.5);
  }
  void feed_until(double t_s) {
    for (; next < imu.samples.size() && imu.samples[next].t_s <= t_s + 1e-9; ++next) {
      const ImuVerdict v = predictor.add_imu(imu.samples[next]);
      REQUIRE((v == ImuVerdict::Accepted || v == ImuVerdict::Buffered));
    }
  }
};

}  // namespace epichead::fusion::testing
