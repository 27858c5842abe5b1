#pragma once
// What the Predictor is told: which motion model, the IMU's noise, mount, clock offset and range,
// how late a vision pose may be, the gates and the start-up uncertainties.
#include <Eigen/Core>

#include "epichead/fusion/constant_velocity.h"
#include "epichead/fusion/imu_propagation.h"
#include "epichead/fusion/learnt_gravity.h"

namespace epichead::fusion {

enum class PredictorMode { ImuAided, ConstantVelocity };

// Mode::ImuAided without vision (unaided_update.h, docs/fusion.md "Without vision"): once no pose
// has been applied for after_s, every period_s of IMU time the filter's tilt is updated from the
// accelerometer's down (when the object's down is learnt) and its position held near the last one
// vision verified.
struct UnaidedOptions {
  bool enabled = true;
  double after_s = 0.2;           // no applied pose for this long (six frames at 30 Hz)
  double period_s = 0.2;          // one update of each kind per this much IMU time: the windows
                                  // (gravity_check.window_s) of consecutive ones overlap by half
  // The measured down's 1-sigma per tilt direction: the camera's mean acceleration over the window,
  // which the filter cannot take off while it is unaided (its own velocity then only repeats its
  // own tilt), up to about 0.5 m/s^2 walking (3 deg).
  double down_sigma_rad = 0.05;
  // No tilt update while the mean specific force's magnitude is off g by more than this share of g:
  // the camera accelerates on average along gravity, and likely across it as well.
  double max_force_error = 0.05;
  // How far from where vision last verified it the camera may be (a robot's step): the position
  // is held within this while the filter's own sigma is larger.
  double position_sigma_m = 0.2;
};

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
  // A reading at or beyond +-range on any axis is saturated (dropped, counted). The defaults are
  // beyond any MEMS sensor (57 000 deg/s, ~1000 g): without the sensor's own range a larger
  // reading is still garbage (a corrupt log, a unit mix-up), never a motion to integrate.
  double gyro_range_radps = 1000;
  double accel_range_mps2 = 10000;
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
  GravityCheckOptions gravity_check;    // Mode::ImuAided: poses checked against the learnt down
  UnaidedOptions unaided;               // Mode::ImuAided: tilt and position while vision is absent
};

}  // namespace epichead::fusion
