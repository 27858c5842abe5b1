#include "epichead/sim/imu_model.h"

#include <algorithm>
#include <cmath>

#include "saturate.h"
#include "simulate_random.h"

namespace epichead::sim {
namespace {

Eigen::Vector3d normal3(Random& rng) { return {rng.normal(), rng.normal(), rng.normal()}; }

}  // namespace

void true_imu(const Kinematics& world_T_imu, Eigen::Vector3d& gyro_radps, Eigen::Vector3d& accel_mps2) {
  const Eigen::Matrix3d Rt = world_T_imu.pose.linear().transpose();
  gyro_radps = Rt * world_T_imu.omega_radps;
  accel_mps2 = Rt * (world_T_imu.accel_mps2 - gravity_world());
}

ImuRun simulate_imu(const ImuParams& p, std::uint64_t seed, const std::function<Kinematics(double)>& world_T_imu,
                    double t0_s, double t1_s) {
  ImuRun run;
  Random draw(seed, 21);    // per-run errors
  Random noise(seed, 22);   // per-sample noise
  run.gyro_scale = Eigen::Vector3d::Ones() + p.gyro_scale_error * normal3(draw);
  run.accel_scale = Eigen::Vector3d::Ones() + p.accel_scale_error * normal3(draw);
  run.gyro_bias0_radps = p.gyro_bias_radps * normal3(draw);
  run.accel_bias0_mps2 = p.accel_bias_mps2 * normal3(draw);
  if (!(t1_s >= t0_s) || !(p.rate_hz > 0)) return run;

  const double dt = 1.0 / p.rate_hz;
  const double clock_rate = 1.0 + p.clock_drift;
  const auto k0 = static_cast<long long>(std::ceil((p.clock_offset_s + clock_rate * t0_s) * p.rate_hz - 1e-9));
  const auto k1 = static_cast<long long>(std::floor((p.clock_offset_s + clock_rate * t1_s) * p.rate_hz + 1e-9));
  if (k1 < k0) return run;
  run.samples.reserve(static_cast<std::size_t>(k1 - k0 + 1));
  const double gyro_white = p.gyro_noise_radps_rthz * std::sqrt(p.rate_hz);
  const double accel_white = p.accel_noise_mps2_rthz * std::sqrt(p.rate_hz);
  const double gyro_walk = p.gyro_bias_walk_radps_rths * std::sqrt(dt);
  const double accel_walk = p.accel_bias_walk_mps2_rths * std::sqrt(dt);
  const double drop_start_p = p.dropouts_per_s * dt;
  const long long drop_len = std::max(1LL, std::llround(p.dropout_s * p.rate_hz));
  Eigen::Vector3d gyro_bias = run.gyro_bias0_radps, accel_bias = run.accel_bias0_mps2;
  long long dropping = 0;
  for (long long k = k0; k <= k1; ++k) {
    ImuSample s;
    s.t_device_s = static_cast<double>(k) * dt;
    s.t_true_s = (s.t_device_s - p.clock_offset_s) / clock_rate;
    true_imu(world_T_imu(s.t_true_s), s.gyro_true_radps, s.accel_true_mps2);
    // Noise is drawn for every sample, dropped or not, so a dropout does not shift later noise.
    const Eigen::Vector3d gn = normal3(noise), an = normal3(noise);
    const Eigen::Vector3d gw = normal3(noise), aw = normal3(noise);
    const double u = noise.uniform();
    s.gyro_radps = run.gyro_scale.cwiseProduct(s.gyro_true_radps) + gyro_bias + gyro_white * gn;
    s.accel_mps2 = run.accel_scale.cwiseProduct(s.accel_true_mps2) + accel_bias + accel_white * an;
    const bool g_clip = saturate(s.gyro_radps, p.gyro_range_radps);
    const bool a_clip = saturate(s.accel_mps2, p.accel_range_mps2);
    if (dropping == 0 && u < drop_start_p) dropping = drop_len;
    if (dropping > 0) {
      s.dropped = true;
      --dropping;
      ++run.dropped;
    } else if (g_clip || a_clip) {
      ++run.saturated;
    }
    gyro_bias += gyro_walk * gw;
    accel_bias += accel_walk * aw;
    run.samples.push_back(s);
  }
  return run;
}

}  // namespace epichead::sim
