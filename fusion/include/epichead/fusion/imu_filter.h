#pragma once
// The IMU-aided filter behind the Predictor (Mode::ImuAided): IMU samples are propagated as they
// come and kept with the state after each in the StateHistory; a vision pose for an exposure time
// in the past is applied at that time and the kept samples are re-propagated up to the newest
// one. Nothing allocates after construction.
#include <cstdint>
#include <optional>

#include <Eigen/Geometry>

#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/nav_state.h"
#include "epichead/fusion/pose_filter.h"
#include "epichead/fusion/predictor_options.h"
#include "epichead/fusion/state_history.h"

namespace epichead::fusion {

class ImuFilter final : public PoseFilter {
 public:
  // Sizes the history for buffer_s at imu_rate_hz (options checked by the caller).
  explicit ImuFilter(const PredictorOptions& options);

  // Keeps a sample (camera clock, newer than the newest kept one) and propagates the newest state
  // to it; false when there is no state yet (the sample is only kept, for initialisation).
  bool add(const ImuSample& sample);

  // PoseFilter. Initialisation takes gravity from the accelerometer over gravity_average_s before
  // t_s and re-propagates the later samples; an update is applied at t_s from the kept state
  // before it (empty: t_s older than the history).
  bool initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) override;
  std::optional<PoseUpdateResult> update(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov,
                                         double gate_chi2) override;
  std::optional<PosePrediction> predict(double t_s) const override;
  double update_t_s() const override;
  void reset() override { history_.drop_states(); }

  // Forgets samples too (a restarted device clock).
  void clear() { history_.clear(); }
  // The next initialisation takes velocity, biases and gravity (with their covariance) from here.
  void carry_motion(const NavState& motion, const ErrorCovariance& covariance);
  void drop_carried_motion() { carry_pending_ = false; }

  const StateHistory& history() const { return history_; }
  // The newest state (sample or anchor); null before initialisation.
  const StateEntry* newest_state() const { return history_.newest_state(); }
  // The newest sample's entry when it carries a state, for an update in place at that sample (the
  // unaided updates); null otherwise. A later vision pose older than it re-propagates over it.
  StateEntry* newest_sample_state();
  std::uint64_t repropagated_samples() const { return repropagated_samples_; }

 private:
  // The filter state at t_s from the nearest earlier kept state; false when there is none.
  bool state_at(double t_s, StateEntry& out, double& extrapolated_s) const;
  // propagate() plus the dropout inflation for a step longer than dropout_gap_s.
  void step(NavState& x, ErrorCovariance& P, const ImuSample& from, const ImuSample& to) const;
  // Re-propagates the entries after t_s from the anchor.
  void repropagate_after(double t_s);
  // cov plus the pose's motion over the time offset's uncertainty (imu_time_offset_sigma_s).
  Matrix6d with_timing_uncertainty(double t_s, const StateEntry& at_t, const Matrix6d& cov) const;

  PredictorOptions options_;
  StateHistory history_;
  std::uint64_t repropagated_samples_ = 0;
  bool carry_pending_ = false;  // carry_motion() given for the next initialisation
  NavState carried_;
  ErrorCovariance carried_P_ = ErrorCovariance::Zero();
};

}  // namespace epichead::fusion
