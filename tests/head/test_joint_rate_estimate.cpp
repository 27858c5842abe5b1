#include <catch2/catch.hpp>

#include <cmath>

#include "epichead/head/joint_rate_estimate.h"

using epichead::head::JointRateEstimate;
using epichead::head::JointRateEstimateOptions;

namespace {

JointRateEstimateOptions options() {
  JointRateEstimateOptions o;
  o.command_delay_s = 0.002;
  o.correction_time_constant_s = 0.05;
  o.max_command_age_s = 0.05;
  return o;
}

}  // namespace

TEST_CASE("joint rates: without a command the estimate is the measured rate", "[head][joint_rates]") {
  JointRateEstimate e(options());
  CHECK(e.at(1.0).isZero());
  e.measured(1.0, {0.3, -0.2});
  CHECK(e.at(1.001).isApprox(Eigen::Vector2d(0.3, -0.2)));
}

TEST_CASE("joint rates: the estimate at an instant is the command sent command_delay_s before it", "[head][joint_rates]") {
  JointRateEstimate e(options());
  for (int i = 0; i <= 10; ++i) e.sent(1.0 + i * 0.001, {0.1 * i, -0.1 * i});
  // At 1.0075 the command in force 2 ms earlier was the one sent at 1.005.
  CHECK(e.at(1.0075).isApprox(Eigen::Vector2d(0.5, -0.5)));
  CHECK(e.at(1.012).isApprox(Eigen::Vector2d(1.0, -1.0)));
  // Before the first command's delay has passed: nothing sent yet that acts, so the measurement (none: 0).
  CHECK(e.at(1.001).isZero());
  // Long after the last command: it no longer says anything, the measurement is used.
  e.measured(1.2, {0.7, 0.7});
  CHECK(e.at(1.2).isApprox(Eigen::Vector2d(0.7, 0.7)));
}

TEST_CASE("joint rates: a joint slower than commanded pulls the estimate toward the measurement over the correction time",
          "[head][joint_rates]") {
  JointRateEstimate e(options());
  // Pan commanded at 1 rad/s but blocked (measured 0); tilt follows.
  double t = 0;
  for (int i = 0; i < 400; ++i, t += 0.001) {
    e.sent(t, {1.0, 0.5});
    if (i % 5 == 0) e.measured(t, {0.0, 0.5});
  }
  // Eight time constants: the correction has taken out the pan command; tilt needs none.
  CHECK(e.at(t).x() == Approx(0.0).margin(0.01));
  CHECK(e.at(t).y() == Approx(0.5).margin(1e-9));
  CHECK(e.correction().x() == Approx(-1.0).margin(0.01));
  e.reset();
  CHECK(e.correction().isZero());
}

TEST_CASE("joint rates: a command older than the last is ignored, the store wraps without losing the newest",
          "[head][joint_rates]") {
  JointRateEstimate e(options());
  for (int i = 0; i < 200; ++i) e.sent(i * 0.001, {static_cast<double>(i), 0});
  e.sent(0.05, {-99, -99});  // out of order: ignored
  CHECK(e.at(0.199 + 0.002).x() == Approx(199));
  CHECK(e.at(0.150 + 0.0025).x() == Approx(150));
}

TEST_CASE("joint rates: with a motor lag the estimate follows a commanded step as a first-order lag after the delay",
          "[head][joint_rates]") {
  JointRateEstimateOptions o = options();
  o.motor_lag_s = 0.010;
  JointRateEstimate e(o);
  e.measured(0.0, {0, 0});
  // A step to 1 and -2 rad/s at t = 0, commanded every millisecond; asked as time goes on.
  for (int i = 0; i <= 100; ++i) {
    e.sent(i * 0.001, {1.0, -2.0});
    const double t = i * 0.001 + 0.0005;
    const double f = t < 0.002 ? 0.0 : 1 - std::exp(-(t - 0.002) / 0.010);
    INFO("t " << t);
    CHECK(e.at(t).x() == Approx(1.0 * f).margin(1e-9));
    CHECK(e.at(t).y() == Approx(-2.0 * f).margin(1e-9));
  }
}

TEST_CASE("joint rates: with backlash the estimate is the output side's, the correction compares the motor side",
          "[head][joint_rates]") {
  JointRateEstimate e(options());
  // The motor crosses a dead band at 0.3 rad/s while the output rests.
  for (int i = 0; i <= 100; ++i) {
    e.sent(1.0 + i * 0.001, {0.3, -0.2}, {0.0, -0.2});
    // The encoder measures the motor: the motor-side model agrees, nothing to correct.
    if (i % 5 == 0) e.measured(1.0 + i * 0.001 + 0.0025, {0.3, -0.2});
  }
  CHECK(e.correction().norm() < 1e-12);
  CHECK(e.at(1.05).isApprox(Eigen::Vector2d(0.0, -0.2)));
}
