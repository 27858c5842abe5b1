#pragma once
// The buffered predictor the tracker loop talks to. It checks and counts every input, and runs one
// of two filters behind the same interface (pose_filter.h): with IMU (Mode::ImuAided, imu_filter.h)
// samples are propagated as they come and kept with the state after each for about buffer_s, and
// a vision pose for an exposure time in the past is applied at that time and the kept samples
// re-propagated; without IMU (Mode::ConstantVelocity) a constant-twist filter on the vision poses
// (constant_velocity.h) does the same job. Start-up, gating and re-initialisation are the
// Predictor's, the same for both. predict(t) gives the pose at any time for window placement.
// Nothing allocates after construction.
#include <cstdint>
#include <expected>
#include <optional>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/fusion/constant_velocity.h"
#include "epichead/fusion/imu_filter.h"
#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/learnt_gravity.h"
#include "epichead/fusion/nav_state.h"
#include "epichead/fusion/pose_filter.h"
#include "epichead/fusion/pose_prediction.h"
#include "epichead/fusion/predictor_options.h"

namespace epichead::fusion {

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
  AgainstGravity,  // ImuAided: a (re-)initialisation refused, the pose's tilt contradicts the
                   // learnt down (learnt_gravity.h)
  Unchecked,       // ImuAided: a re-initialisation after gated poses refused while the down is
                   // learnt but cannot be measured at the exposure (the window is cut by a gap):
                   // right after an IMU gap the tracker's pose may be a tilted wrong lock
};

const char* to_string(ImuVerdict verdict);
const char* to_string(VisionVerdict verdict);
// Whether a tracked pose with this verdict supersedes a start pose (init.csv, the robot's
// init_pose) as the filter's seed: it started or updated the filter, or the filter could not yet
// take any pose then (no IMU sample before it, or too old). `track` and the onboard loop alike.
inline bool supersedes_start_pose(VisionVerdict v) {
  return v == VisionVerdict::NoImu || v == VisionVerdict::TooOld || v == VisionVerdict::Initialised || v == VisionVerdict::Applied;
}

struct VisionResult {
  VisionVerdict verdict = VisionVerdict::BadInput;
  double mahalanobis2 = 0;  // squared Mahalanobis distance of the innovation (Applied, Gated)
  int dims = 6;             // its degrees of freedom: 5 for a pose with a free direction (free_direction.h)
};

struct PredictorCounters {
  std::uint64_t imu_accepted = 0, imu_buffered = 0, imu_non_finite = 0, imu_saturated = 0, imu_out_of_order = 0,
                imu_duplicate = 0, imu_time_jump = 0, imu_ignored = 0;
  std::uint64_t imu_restarts = 0;    // streams restarted after a time jump
  std::uint64_t dropouts = 0;        // gaps longer than dropout_gap_s
  double dropout_total_s = 0;        // summed length of those gaps
  std::uint64_t vision_applied = 0, vision_initialised = 0, vision_gated = 0, vision_too_old = 0,
                vision_out_of_order = 0, vision_bad_input = 0, vision_no_imu = 0;
  std::uint64_t vision_against_gravity = 0;  // poses check_tilt() or a re-initialisation found tilted
  std::uint64_t gravity_forgotten = 0;       // learnt downs forgotten: a long run of contradictions, or learnt from a replaced wrong lock
  std::uint64_t vision_unchecked = 0;        // re-initialisations refused: tilt not measurable (Unchecked)
  std::uint64_t unaided_down_updates = 0;    // tilt updates from the accelerometer without vision
  std::uint64_t unaided_tilt_contradictions = 0;  // of those, the filter's own tilt contradicted gravity
  std::uint64_t unaided_position_holds = 0;  // position held near the last verified one without vision
  std::uint64_t unaided_pose_floors = 0;     // pose covariance raised to the last vision pose's on going unaided
  std::uint64_t resumption_resets = 0;       // re-initialisations from a gated pose after a gap (of reinitialisations)
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
  bool gravity_learnt = false;     // check_tilt() can tell a tilted pose
  bool gravity_told = false;       // ... by the down the user told (GravityCheckOptions::told_down_obj)
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
  // The down (unit) the accelerometer measures in the camera frame at t_s (learnt_gravity.h); empty
  // in Mode::ConstantVelocity or without enough recent samples.
  std::optional<Eigen::Vector3d> measured_down_cam(double t_s) const;
  // The object's down in its own frame, learnt while vision and the IMU agreed; empty before.
  std::optional<Eigen::Vector3d> learnt_down_obj() const;
  // How far a pose exposed at t_s tilts the object's learnt down from the down the accelerometer
  // measures then (rad); empty in Mode::ConstantVelocity, before a down is learnt, or without
  // enough recent samples. Kept across reset().
  std::optional<double> tilt_error_rad(double t_s, const Eigen::Isometry3d& cam_T_obj) const;
  // True when that error exceeds options().gravity_check.max_tilt_error_rad: the tracker's pose is
  // a wrong lock whatever its support; the caller takes the frame as lost (and detects again).
  // Counted, and a long run of them forgets the learnt down (the object was moved).
  bool check_tilt(double t_s, const Eigen::Isometry3d& cam_T_obj);
  // The same verdict on an error already measured by tilt_error_rad(t_s, ...) (a caller that
  // reports the error too need not measure it twice); an empty error is no verdict (false).
  bool check_tilt(double t_s, std::optional<double> error_rad);
  // The tracked poses since lock_since_s were a wrong lock, replaced by `cam_T_obj` exposed at t_s
  // (a detection explained the image better). A learnt down first learnt since then, which this
  // pose contradicts, was the lock's, and is forgotten (counted in gravity_forgotten); one learnt
  // before is kept (the replacing pose's own tilt is then the likelier error). True when forgotten.
  bool replace_wrong_lock(double t_s, const Eigen::Isometry3d& cam_T_obj, double lock_since_s);
  PredictorStatus status(double now_t_s) const;
  // Forgets the state (not the buffered samples): the next pose initialises again.
  void reset();
  // Starts again from a vision pose that overrules the filter's (the caller decided the filter was
  // off, vision right), keeping what the IMU measured of the camera's motion: velocity, biases and
  // gravity, turned from the filter's object frame into the pose's (in the camera frame, where
  // the IMU measures them, they stay). The pose is checked as a first pose is (check_tilt).
  // A restart from defaults starts the velocity at zero and gravity from the accelerometer's mean:
  // in a hand-held motion the translation then ran off 10-15 mm a frame (development lampshade 5,
  // tools/track_prediction.cpp's restarts; docs/fusion.md, "Gated poses that agree").
  VisionResult restart_keeping_motion(double exposure_t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov);
  // The next initialisation takes velocity, biases and gravity direction (and their variances)
  // from `motion` instead of the defaults: for a restart on a corrected clock (the camera-IMU
  // time offset just estimated) while the motion state learnt so far still holds. A restart from
  // defaults in the middle of a shake initialises gravity from moving readings and the velocity
  // as unknown, and the translation runs off before vision can pull it back (box_clutter).
  void carry_motion(const NavState& motion, const ErrorCovariance& covariance);
  // Takes the object's learnt down (and its run of contradictions) from another predictor of the
  // same scene: a restart on a corrected clock keeps what the scene's gravity is.
  void carry_learnt_gravity(const Predictor& from) { gravity_ = from.gravity_; }
  // ... and goes on counting from its counters (status().counters), so that a run's counts do not
  // start again at the restart. Samples fed again on the new clock count again in imu_accepted.
  void carry_counters(const Predictor& from) { status_.counters = from.status_.counters; }

  // The newest filter state (ImuAided), for diagnostics and tests; empty before initialisation.
  std::optional<NavState> state() const;
  const ErrorCovariance& covariance() const;
  double state_t_s() const;
  const PredictorOptions& options() const { return options_; }

 private:
  explicit Predictor(const PredictorOptions& options);
  // Without vision for options_.unaided.after_s: the tilt and position updates of unaided_update.h
  // on the state of the sample at t_s (the newest), once per options_.unaided.period_s.
  void update_unaided(double t_s);
  // After an applied or initialising pose at t_s: its camera position (the filter's, after the
  // update) becomes the one the unaided filter is held near, unless the accelerometer could not
  // check the pose's tilt or contradicted it.
  void note_hold(double t_s, const Eigen::Isometry3d& cam_T_obj);
  // The first pose, or the first after reset / a run of gated poses / a gap (never from a tilted
  // lock: the learnt down decides).
  VisionResult initialise_from(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov);
  // A gated pose at t_s more than unaided.after_s after the last applied one, within
  // unaided.position_sigma_m of the held position: re-initialise from it (ImuAided only).
  bool resumes_after_gap(double t_s, const Eigen::Isometry3d& cam_T_obj) const;
  // The newest state's biases and gravity direction (with their covariance) for the next
  // initialisation; its velocity is forgotten (zero, initial_speed_mps).
  void carry_sensor_state();
  // After an applied or initialising pose: its covariance, for the unaided pose floor.
  void note_vision_cov(const Matrix6d& cov);
  // The filter of options_.mode.
  PoseFilter& filter();
  const PoseFilter& filter() const;

  PredictorOptions options_;
  ImuFilter imu_;
  ConstantVelocityFilter cv_;
  int jumps_in_a_row_ = 0;    // TimeJump samples in a row, each in order after the previous
  double last_jump_t_s_ = 0;  // time of the newest of them
  bool initialised_ = false;
  bool reinit_pending_ = false;
  int applied_in_a_row_ = 0;
  LearntGravity gravity_;
  double next_down_t_s_ = 0, next_hold_t_s_ = 0;  // the next unaided updates are due at these sample times
  // The camera position after the last applied pose that the accelerometer did not contradict
  // (or any, before a down is learnt): where the unaided filter is held.
  bool have_hold_ = false;
  Eigen::Vector3d hold_obj_p_cam_ = Eigen::Vector3d::Zero();
  // The last applied or initialising pose's covariance (vision's order): the floor of the
  // filter's pose covariance once it goes unaided (floor_pose_covariance), taken once per stretch.
  Matrix6d last_vision_cov_ = Matrix6d::Zero();
  bool unaided_floored_ = true;
  PredictorStatus status_;
};

}  // namespace epichead::fusion
