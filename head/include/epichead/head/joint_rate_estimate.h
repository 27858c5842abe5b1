#pragma once
// The joints' rates at a recent instant, for body rate = gyro - J q_dot. The measured head state
// is too coarse for that subtraction: it arrives at 200 Hz, late and quantised, while the gyro
// already sees the joints' motion of its own sample instant; the mismatch feeds straight back
// into the next command and makes the loop chatter. The controller's own commands are exactly
// timed at the loop rate and the firmware follows their rate (feed-forward) after a short,
// known delay and, on a slow head, a first-order lag: the estimate is the commanded rate passed
// through that delay and lag (a model of the head), plus a slowly low-passed correction toward
// what the head state measures (a joint that is slower than the model, blocked or stuck).
// Without a recent command it is the measured rate. With gear backlash the camera moves with the
// output shaft, not the motor: the controller then also gives the output-side rate of each
// command (zero while the motor crosses the dead band, backlash_compensation.h); the estimate is
// that rate through the same delay and lag, while the correction still compares the motor-side
// model with the measurement (the encoder is on the motor).
// Fixed storage, no allocation.
#include <cstddef>

#include <Eigen/Core>

#include "epichead/common/ring_buffer.h"

namespace epichead::head {

struct JointRateEstimateOptions {
  double command_delay_s = 0.0005;        // command sent -> joints start moving to its rate (bus + firmware)
  double motor_lag_s = 0;                 // then the joint rate follows with this first-order lag
  double correction_time_constant_s = 0.05;  // measured-vs-commanded correction's low-pass
  double max_command_age_s = 0.05;        // an older command says nothing about now: use the measurement
};

class JointRateEstimate {
 public:
  explicit JointRateEstimate(const JointRateEstimateOptions& options = {}) : options_(options) {}

  // A command put on the bus at t_s with these pan/tilt rates. Times must not go back (an
  // earlier one is ignored).
  void sent(double t_s, const Eigen::Vector2d& rates_radps) { sent(t_s, rates_radps, rates_radps); }
  // The same, with the rates the output shafts get from it (they differ from the motors' while
  // a dead band is crossed).
  void sent(double t_s, const Eigen::Vector2d& rates_radps, const Eigen::Vector2d& output_rates_radps);
  // A head state measured (received) at t_s.
  void measured(double t_s, const Eigen::Vector2d& rates_radps);
  // The estimate at t_s (output side).
  Eigen::Vector2d at(double t_s) const;
  // Forget commands and correction (after the head stopped following: bus-off, stale state).
  void reset();

  const Eigen::Vector2d& correction() const { return correction_; }

 private:
  // A command from the moment it acts (sent + command_delay_s) and the modelled joint rate then,
  // motor and output side.
  struct Sent {
    double t_s = 0;
    Eigen::Vector2d command_radps = Eigen::Vector2d::Zero();
    Eigen::Vector2d model_radps = Eigen::Vector2d::Zero();
    Eigen::Vector2d output_command_radps = Eigen::Vector2d::Zero();
    Eigen::Vector2d output_model_radps = Eigen::Vector2d::Zero();
  };
  // The command acting at t_s, or null (none yet, or too old to say anything).
  const Sent* in_force(double t_s) const;
  // The modelled joint rate at t_s from `model` at s.t_s under `command`: the lag pulls it toward
  // the command.
  Eigen::Vector2d lagged(const Eigen::Vector2d& command, const Eigen::Vector2d& model, double from_t_s, double t_s) const;
  Eigen::Vector2d model_at(const Sent& s, double t_s) const { return lagged(s.command_radps, s.model_radps, s.t_s, t_s); }
  Eigen::Vector2d output_model_at(const Sent& s, double t_s) const {
    return lagged(s.output_command_radps, s.output_model_radps, s.t_s, t_s);
  }

  JointRateEstimateOptions options_;
  // The commands sent, a new one overwriting the oldest: 64 ms at 1 kHz, more than any delay asked for.
  common::RingBuffer<Sent, 64> sent_;
  bool have_measured_ = false;
  double measured_t_s_ = 0;
  Eigen::Vector2d measured_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d correction_ = Eigen::Vector2d::Zero();
};

}  // namespace epichead::head
