#pragma once
// The buffered predictor the tracker loop talks to. IMU samples are propagated as they come and
// kept (with the state after each) in a fixed ring of about buffer_s; a vision pose for an exposure
// time in the past is applied at that time and the stored samples are re-propagated up to the
// newest one. predict(t) gives the pose at any time for window placement. Without IMU
// (Mode::ConstantVelocity) a constant-twist filter on the vision poses does the same job.
// Every rejected input is counted; nothing allocates after construction.
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/fusion/constant_velocity.h"
#include "epichead/fusion/imu_propagation.h"
#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/nav_state.h"
#include "epichead/fusion/pose_prediction.h"

namespace epichead::fusion {

enum class PredictorMode { ImuAided, ConstantVelocity };

struct PredictorOptions {
  PredictorMode mode = PredictorMode::ImuAided;
  ImuNoise imu_noise;
  ImuMount mount;                       // cam_R_imu
  double imu_time_offset_s = 0;         // t_camera = t_imu - offset
  // 1-sigma of imu_time_offset_s. A vision pose's time on the IMU clock is then uncertain by this
  // much, so its covariance grows by the pose's own motion over that time (rate x sigma): while
  // the camera turns fast, a pose from a clock that may be 20 ms off is no better than ~1 deg,
  // however sharp the image. 0: the offset is exact.
  double imu_time_offset_sigma_s = 0;
  double imu_rate_hz = 1000;            // nominal; sizes the ring
  double buffer_s = 0.5;                // how late a vision pose may be
  double gyro_range_radps = 1e300;      // a reading at or beyond +-range on any axis is saturated
  double accel_range_mps2 = 1e300;
  double dropout_gap_s = 0.0035;        // a gap between samples longer than this is a dropout
  // Over a gap the readings are unknown, not linear: the error covariance of a step longer than
  // dropout_gap_s (and of an extrapolation that long) grows by a random rate and acceleration of
  // these sizes held over the step (docs/fusion.md).
  double dropout_gyro_sigma_radps = 1.0;
  double dropout_accel_sigma_mps2 = 2.0;
  double coast_after_s = 0.02;          // status().coasting when the newest sample is older than this
  double gate_chi2 = 22.46;             // chi-square, 6 dof, p = 0.999
  int reinit_after_gated = 5;           // this many gated poses in a row: re-initialise on the next
  double gravity_average_s = 0.1;       // accelerometer averaging window before the first pose
  double initial_gravity_rad = 0.05;    // 1-sigma of the gravity direction at init (plus motion, see docs)
  double initial_speed_mps = 0.5;       // 1-sigma of the velocity at init
  double initial_gyro_bias_radps = 0.02;
  double initial_accel_bias_mps2 = 0.2;
  ConstantVelocityNoise cv_noise;       // Mode::ConstantVelocity
};

// What add_imu did with a sample.
enum class ImuVerdict {
  Accepted,    // propagated (and buffered)
  Buffered,    // kept for initialisation: no vision pose yet
  NonFinite,   // NaN or infinity in time or a reading: rejected
  Saturated,   // an axis at or beyond its range: rejected
  OutOfOrder,  // older than the newest sample or update: rejected
  Duplicate,   // same time as the newest sample: rejected
  TimeJump,    // more than buffer_s from the newest sample (either way): rejected, unless the stream
               // stays there (3 such samples in a row restart it: ring and state dropped)
  Ignored,     // Mode::ConstantVelocity
};

// What add_vision did with a pose.
enum class VisionVerdict {
  Applied,      // Kalman update at the exposure time, later samples re-propagated
  Initialised,  // first pose (or first after reset / a run of gated poses)
  Gated,        // Mahalanobis distance beyond the gate: rejected
  TooOld,       // older than the buffered samples: rejected
  OutOfOrder,   // older than the last applied pose: rejected
  BadInput,     // non-finite pose or covariance, covariance not positive definite, or an
                // exposure time more than buffer_s after the newest sample
  NoImu,        // ImuAided: no accelerometer reading near the exposure time to initialise gravity
};

const char* to_string(ImuVerdict verdict);
const char* to_string(VisionVerdict verdict);

struct VisionResult {
  VisionVerdict verdict = VisionVerdict::BadInput;
  double mahalanobis2 = 0;  // squared Mahalanobis distance of the innovation (Applied, Gated)
};

struct PredictorCounters {
  std::uint64_t imu_accepted = 0, imu_buffered = 0, imu_non_finite = 0, imu_saturated = 0, imu_out_of_order = 0,
                imu_duplicate = 0, imu_time_jump = 0, imu_ignored = 0;
  std::uint64_t imu_restarts = 0;    // streams restarted after a time jump
  std::uint64_t dropouts = 0;        // gaps longer than dropout_gap_s
  double dropout_total_s = 0;        // summed length of those gaps
  std::uint64_t vision_applied = 0, vision_initialised = 0, vision_gated = 0, vision_too_old = 0,
                vision_out_of_order = 0, vision_bad_input = 0, vision_no_imu = 0;
  std::uint64_t reinitialisations = 0;  // initialisations after the first (reset or gated run)
  std::uint64_t repropagated_samples = 0;
};

struct PredictorStatus {
  bool initialised = false;
  bool coasting = false;           // ImuAided and initialised: no IMU sample for > coast_after_s at now_t_s
  double newest_imu_t_s = 0;       // camera clock
  double last_update_t_s = 0;      // exposure time of the last applied or initialising pose
  double last_nis = 0;             // normalised innovation squared of the last applied pose (6 dof)
  int gated_in_a_row = 0;
  PredictorCounters counters;
};

class Predictor {
 public:
  // Checks the options (finite, positive where needed) and sizes the ring.
  static std::expected<Predictor, std::string> create(const PredictorOptions& options);

  ImuVerdict add_imu(const ImuSample& sample);
  VisionResult add_vision(double exposure_t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov);
  // The pose at t_s (camera clock); empty before initialisation or before the oldest kept state.
  std::optional<PosePrediction> predict(double t_s) const;
  PredictorStatus status(double now_t_s) const;
  // Forgets the state (not the buffered samples): the next pose initialises again.
  void reset();
  // The next initialisation takes velocity, biases and gravity direction (and their variances)
  // from `motion` instead of the defaults: for a restart on a corrected clock (the camera-IMU
  // time offset just estimated) while the motion state learnt so far still holds. A restart from
  // defaults in the middle of a shake initialises gravity from moving readings and the velocity
  // as unknown, and the translation runs off before vision can pull it back (box_clutter).
  void carry_motion(const NavState& motion, const ErrorCovariance& covariance);

  // The newest filter state (ImuAided), for diagnostics and tests; empty before initialisation.
  std::optional<NavState> state() const;
  const ErrorCovariance& covariance() const;
  double state_t_s() const;
  const PredictorOptions& options() const { return options_; }

 private:
  // One buffered sample (camera clock) and the filter state right after it.
  struct Entry {
    ImuSample sample;
    NavState x;
    ErrorCovariance P;
  };
  // cov plus the pose's motion over the time offset's uncertainty (imu_time_offset_sigma_s).
  Matrix6d with_timing_uncertainty(double t_s, const Entry& at_t, const Matrix6d& cov) const;
  // The state right after the last vision pose, at its exposure time (between two samples).
  // Its sample is the reading at that time (interpolated between neighbours, or held).
  struct Anchor {
    bool valid = false;
    Entry e;
  };

  explicit Predictor(const PredictorOptions& options);
  Entry& at(std::uint64_t seq) { return ring_[seq % ring_.size()]; }
  const Entry& at(std::uint64_t seq) const { return ring_[seq % ring_.size()]; }
  std::uint64_t oldest_seq() const { return end_seq_ - count_; }
  // Newest buffered sample with t <= t_s (nullopt when none).
  std::optional<std::uint64_t> find_at_or_before(double t_s) const;
  // The filter state at t_s from the nearest earlier stored state; false when there is none.
  bool state_at(double t_s, Entry& out, double& extrapolated_s) const;
  // The newest state: the newest valid entry or the anchor, whichever is later.
  const Entry* newest_state() const;
  void repropagate_after(double t_s);
  // propagate() plus the dropout inflation for a step longer than dropout_gap_s.
  void step(NavState& x, ErrorCovariance& P, const ImuSample& from, const ImuSample& to) const;
  VisionResult initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov);
  VisionResult add_vision_cv(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov);

  PredictorOptions options_;
  std::vector<Entry> ring_;
  std::uint64_t end_seq_ = 0;   // sequence number after the newest entry
  std::uint64_t count_ = 0;     // entries held
  std::uint64_t valid_from_seq_ = 0;  // entries from here on carry a valid state
  Anchor anchor_;
  double evicted_t_s_ = -1e300;
  int jumps_in_a_row_ = 0;       // TimeJump samples in a row, each in order after the previous
  double last_jump_t_s_ = 0;  // newest sample pushed out of the ring: the anchor is unusable before it
  bool initialised_ = false;
  bool reinit_pending_ = false;
  bool carry_pending_ = false;  // carry_motion() given for the next initialisation
  NavState carried_;
  ErrorCovariance carried_P_ = ErrorCovariance::Zero();
  ConstantVelocityFilter cv_;
  PredictorStatus status_;
};

}  // namespace epichead::fusion
