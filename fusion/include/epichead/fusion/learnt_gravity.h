#pragma once
// Which is wrong when vision and the IMU disagree? The accelerometer is the one absolute reference
// besides the image: the object is static, so its "down" (gravity in the object frame) is a
// constant of the scene. LearntGravity keeps it, learnt slowly from the filter while vision and
// the IMU agree, and kept across resets and re-initialisations; measured_down_imu() gives the
// down the accelerometer measures at a frame's exposure. A pose that tilts the object's learnt
// down away from the measured one by more than a few degrees is a wrong lock (an edge of clutter,
// a printed band), whatever the image's support; one that agrees is at least right in tilt.
// After a gap in the IMU a wrong lock was mostly a tilt (sim-run, bus-off inside a walking step:
// 18 deg off, 17-18 deg of it tilt), which this sees; a turn about gravity it cannot see.
#include <cstdint>
#include <optional>

#include <Eigen/Core>

#include "epichead/fusion/state_history.h"

namespace epichead::fusion {

struct GravityCheckOptions {
  bool enabled = true;
  // Learning: once the filter has applied this many vision poses in a row and its gravity
  // direction's 1-sigma is below learn_sigma_rad, the learnt down moves towards the filter's with
  // time constant learn_time_s (slow, so that a lock drifting off pulls it only a little).
  int learn_after_applied = 30;
  double learn_sigma_rad = 0.03;
  double learn_time_s = 5.0;
  // Measuring: the accelerometer averaged over up to window_s before the exposure (at least
  // min_window_s without a dropout), turned to the exposure's IMU frame by the gyro. The mean of
  // a walking camera's acceleration over that long is what limits it (docs/fusion.md).
  double window_s = 0.4;
  double min_window_s = 0.15;
  // A pose whose tilt is off by more than this contradicts gravity.
  double max_tilt_error_rad = 0.17;  // ~10 deg
  // Contradictions with no agreeing pose between for this long: the object was moved (its down
  // changed), so the learnt down is forgotten and learnt again.
  double forget_after_s = 5.0;
  // A body of revolution (the tracker's free turn): its poses' turn about this axis (object
  // frame, unit) is arbitrary, so only the angle between the axis and the down is checked.
  std::optional<Eigen::Vector3d> free_turn_axis_obj;
  // The object's down told by the user (object frame; a box standing on its base: minus its up).
  // Then the down is known from the first frame instead of learnt from 30 applied poses, and a
  // start that is wrong for a while cannot teach a wrong one (docs/fusion.md). Learning still
  // takes the IMU biases. Forgotten like a learnt down (the object was moved), then learnt.
  std::optional<Eigen::Vector3d> told_down_obj;
};

class LearntGravity {
 public:
  explicit LearntGravity(const GravityCheckOptions& options);

  // After an applied vision pose at t_s: the filter's down in the object frame, its 1-sigma (rad),
  // its IMU biases, and how many poses it has applied in a row.
  void learn(double t_s, const Eigen::Vector3d& down_obj, double sigma_rad, const Eigen::Vector3d& gyro_bias_radps,
             const Eigen::Vector3d& accel_bias_mps2, int applied_in_a_row);
  // How far the pose's tilt is from the measured down (rad); empty before anything is learnt or
  // without a measurement. With a free turn axis: how far the axis's angle to the down is.
  std::optional<double> tilt_error_rad(const Eigen::Matrix3d& cam_R_obj, const std::optional<Eigen::Vector3d>& down_cam) const;
  // A pose at t_s was found to contradict (true) or agree with (false) gravity; forgets the learnt
  // down after forget_after_s of contradictions with none agreeing.
  void note_verdict(double t_s, bool contradicts);
  // The poses it was learnt from were a wrong lock (a recheck found the object elsewhere): the
  // learnt down is forgotten and learnt again. A told one is kept (the caller decides whether the
  // down was the lock's: learnt_since_s()).
  void forget_learnt();

  bool learnt() const { return learnt_; }
  // When the down now held was first learnt (not told); meaningless before.
  double learnt_since_s() const { return learnt_since_s_; }
  // The down is the told one (not yet forgotten).
  bool told() const { return told_; }
  // gyro_bias_radps() and accel_bias_mps2() come from the filter (a told down has none at first).
  bool biases_learnt() const { return biases_learnt_; }
  const Eigen::Vector3d& down_obj() const { return down_obj_; }
  // The learnt down for a pose that puts the measured down at `measured_down_obj` (object
  // frame): the learnt one, or with a free turn axis, of the downs at the learnt angle to the axis
  // (all equally right, the turn being the tracker's choice) the one nearest the measured.
  Eigen::Vector3d down_obj_toward(const Eigen::Vector3d& measured_down_obj) const;
  const Eigen::Vector3d& gyro_bias_radps() const { return gyro_bias_radps_; }
  const Eigen::Vector3d& accel_bias_mps2() const { return accel_bias_mps2_; }
  int forgotten() const { return forgotten_; }
  const GravityCheckOptions& options() const { return options_; }

 private:
  GravityCheckOptions options_;
  bool learnt_ = false;
  bool told_ = false;
  bool biases_learnt_ = false;
  Eigen::Vector3d down_obj_ = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d gyro_bias_radps_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias_mps2_ = Eigen::Vector3d::Zero();
  double learnt_t_s_ = 0;
  double learnt_since_s_ = 0;
  double contradicted_since_s_ = -1;  // first contradiction of the current run; < 0: none
  int forgotten_ = 0;
};

// The specific force (less accel_bias) averaged over the samples of the last window_s up to
// t_s, each turned into the IMU frame of the newest of them by the gyro (less gyro_bias), and the
// samples it spans. It stops at a gap longer than dropout_gap_s (the turn across it is unknown).
// Empty when less than min_window_s is covered.
struct MeanForce {
  Eigen::Vector3d mean_imu_mps2 = Eigen::Vector3d::Zero();
  std::uint64_t oldest_seq = 0, newest_seq = 0;
};
std::optional<MeanForce> mean_specific_force(const StateHistory& history, double t_s, double window_s, double min_window_s,
                                            double dropout_gap_s, const Eigen::Vector3d& gyro_bias_radps,
                                            const Eigen::Vector3d& accel_bias_mps2);

// The down direction (unit) the accelerometer measures in the IMU frame at t_s: the mean specific
// force less the mean acceleration over the window (when known: the filter's velocity change,
// in the same frame), negated. Without it, it assumes no mean acceleration. Empty when the result
// is far from 1 g (a fall, garbage).
std::optional<Eigen::Vector3d> down_from(const MeanForce& force, const Eigen::Vector3d& mean_accel_imu_mps2 = Eigen::Vector3d::Zero());

// mean_specific_force and down_from with no acceleration known.
std::optional<Eigen::Vector3d> measured_down_imu(const StateHistory& history, double t_s, double window_s,
                                                 double min_window_s, double dropout_gap_s,
                                                 const Eigen::Vector3d& gyro_bias_radps,
                                                 const Eigen::Vector3d& accel_bias_mps2);

}  // namespace epichead::fusion
