#pragma once
// A deterministic truth generator for the fusion tests: a smooth camera trajectory with closed-form
// derivatives, the exact IMU readings it produces (specific force with gravity), and seeded noise,
// biases and vision poses drawn from the distributions the filter assumes.
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/fusion/imu_sample.h"
#include "epichead/fusion/nav_state.h"
#include "epichead/geometry/se3.h"

namespace epichead::fusion::testing {

using geometry::Matrix6d;
using geometry::Vector6d;

// Sinusoidal Z-Y-X angles and position about a base pose looking at the object.
struct TrajectoryParams {
  Eigen::Vector3d angle_amp_rad{0.3, 0.25, 0.2};    // alpha (z), beta (y), gamma (x)
  Eigen::Vector3d angle_freq_radps{1.3, 1.7, 2.1};
  Eigen::Vector3d pos_amp_m{0.15, 0.1, 0.12};
  Eigen::Vector3d pos_freq_radps{1.1, 1.9, 1.5};
  Eigen::Vector3d gravity_dir_obj{0.1, 0.95, 0.2};    // object frame; normalised to g
  Eigen::Matrix3d cam_R_imu = Eigen::Matrix3d::Identity();
};

struct TruthPoint {
  NavState x;                       // biases left zero: they belong to the IMU run
  Eigen::Vector3d gyro_cam_radps;   // true rate, camera frame
  Eigen::Vector3d force_cam_mps2;   // true specific force, camera frame
};

class Trajectory {
 public:
  explicit Trajectory(const TrajectoryParams& params = {});
  TruthPoint at(double t_s) const;
  const TrajectoryParams& params() const { return params_; }

 private:
  TrajectoryParams params_;
  Eigen::Matrix3d base_R_;  // obj_R_cam at zero angles: looking from -z of the object at it
  Eigen::Vector3d base_p_;
};

struct ImuErrors {
  double gyro_noise_radps_rthz = 0, accel_noise_mps2_rthz = 0;
  double gyro_bias_walk_radps_rths = 0, accel_bias_walk_mps2_rths = 0;
  double gyro_bias0_sigma_radps = 0, accel_bias0_sigma_mps2 = 0;  // drawn initial bias ...
  Eigen::Vector3d gyro_bias0_radps = Eigen::Vector3d::Zero();       // ... added to these
  Eigen::Vector3d accel_bias0_mps2 = Eigen::Vector3d::Zero();
  double rate_hz = 1000;
  double time_offset_s = 0;  // device stamp = camera time + offset
};

struct ImuRun {
  std::vector<ImuSample> samples;              // device stamps, as the predictor receives them
  std::vector<Eigen::Vector3d> gyro_bias, accel_bias;  // true bias at each sample
};

// Readings on t = k / rate (camera clock) for t in [t0_s, t1_s].
ImuRun simulate_imu(const Trajectory& traj, const ImuErrors& errors, double t0_s, double t1_s, std::uint64_t seed);

// Feeds `imu` to the predictor in order and, after each sample, every vision pose whose exposure
// time (first_vision_s + j / vision_rate_hz) lies at least latency_s in the past, measured with
// noise of `vision_cov`, up to exposure time last_vision_s. `after_sample(k, t_cam_s)` runs after
// sample k has been given.
template <class Predictor, class Callback>
void run_scenario(Predictor& predictor, const Trajectory& traj, const ImuRun& imu, double time_offset_s,
                  double first_vision_s, double vision_rate_hz, double latency_s, const Matrix6d& vision_cov,
                  std::mt19937_64& rng, Callback after_sample, double last_vision_s = 1e300);

// Vision measurement: exp(n) * true cam_T_obj, n ~ N(0, cov) in (translation, rotation).
Eigen::Isometry3d noisy_pose(const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov, std::mt19937_64& rng);

Matrix6d pose_cov(double sigma_m, double sigma_rad);

// Wilson-Hilferty approximation of the chi-square quantile (accurate to < 1 % for dof > 30).
double chi2_quantile(double p, double dof);

inline constexpr double kDegRad = M_PI / 180;

// The angle between two directions, rad (atan2: exact near 0 and pi).
inline double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

template <class Predictor, class Callback>
void run_scenario(Predictor& predictor, const Trajectory& traj, const ImuRun& imu, double time_offset_s,
                  double first_vision_s, double vision_rate_hz, double latency_s, const Matrix6d& vision_cov,
                  std::mt19937_64& rng, Callback after_sample, double last_vision_s) {
  int j = 0;
  for (std::size_t k = 0; k < imu.samples.size(); ++k) {
    predictor.add_imu(imu.samples[k]);
    const double t_cam = imu.samples[k].t_s - time_offset_s;
    for (;;) {
      const double t_exp = first_vision_s + j / vision_rate_hz;
      if (t_exp + latency_s > t_cam + 1e-9 || t_exp > last_vision_s) break;
      predictor.add_vision(t_exp, noisy_pose(traj.at(t_exp).x.cam_T_obj(), vision_cov, rng), vision_cov);
      ++j;
    }
    after_sample(k, t_cam);
  }
}

}  // namespace epichead::fusion::testing
