#include "truth_helpers.h"

#include <cmath>

#include <Eigen/Cholesky>

namespace epichead::fusion::testing {
namespace {

Eigen::Matrix3d rot(const Eigen::Vector3d& axis, double angle) {
  return Eigen::AngleAxisd(angle, axis).toRotationMatrix();
}

double normal_quantile(double p) {
  // Acklam's rational approximation is more than the tests need: bisection on erfc is enough.
  double lo = -10, hi = 10;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (0.5 * std::erfc(-mid / std::sqrt(2.0)) < p) lo = mid; else hi = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

Trajectory::Trajectory(const TrajectoryParams& params) : params_(params) {
  // Camera 1 m in front of the object looking at it along +z, slightly off-axis.
  base_R_ = rot(Eigen::Vector3d::UnitX(), 0.1);
  base_p_ = Eigen::Vector3d(0.05, -0.1, -1.0);
}

TruthPoint Trajectory::at(double t) const {
  const auto& P = params_;
  Eigen::Vector3d ang, rate;
  for (int i = 0; i < 3; ++i) {
    ang[i] = P.angle_amp_rad[i] * std::sin(P.angle_freq_radps[i] * t);
    rate[i] = P.angle_amp_rad[i] * P.angle_freq_radps[i] * std::cos(P.angle_freq_radps[i] * t);
  }
  const Eigen::Matrix3d Rz = rot(Eigen::Vector3d::UnitZ(), ang[0]), Ry = rot(Eigen::Vector3d::UnitY(), ang[1]),
                        Rx = rot(Eigen::Vector3d::UnitX(), ang[2]);
  TruthPoint out;
  out.x.obj_R_cam = Rz * Ry * Rx * base_R_;
  // Angular velocity in the object frame from the Euler rates, then into the camera frame.
  const Eigen::Vector3d omega_obj =
      rate[0] * Eigen::Vector3d::UnitZ() + rate[1] * (Rz * Eigen::Vector3d::UnitY()) + rate[2] * (Rz * Ry * Eigen::Vector3d::UnitX());
  out.gyro_cam_radps = out.x.obj_R_cam.transpose() * omega_obj;
  Eigen::Vector3d accel;
  for (int i = 0; i < 3; ++i) {
    const double w = P.pos_freq_radps[i], a = P.pos_amp_m[i];
    out.x.obj_p_cam[i] = base_p_[i] + a * std::sin(w * t);
    out.x.obj_v_cam[i] = a * w * std::cos(w * t);
    accel[i] = -a * w * w * std::sin(w * t);
  }
  out.x.obj_R_grav = gravity_frame_from(P.gravity_dir_obj);
  out.force_cam_mps2 = out.x.obj_R_cam.transpose() * (accel - out.x.gravity_obj_mps2());
  return out;
}

ImuRun simulate_imu(const Trajectory& traj, const ImuErrors& e, double t0, double t1, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01;
  const auto normal3 = [&] { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)); };
  ImuRun run;
  Eigen::Vector3d bg = e.gyro_bias0_radps + e.gyro_bias0_sigma_radps * normal3();
  Eigen::Vector3d ba = e.accel_bias0_mps2 + e.accel_bias0_sigma_mps2 * normal3();
  const double dt = 1.0 / e.rate_hz;
  const Eigen::Matrix3d imu_R_cam = traj.params().cam_R_imu.transpose();
  for (long k = std::lround(std::ceil(t0 * e.rate_hz)); k * dt <= t1 + 1e-12; ++k) {
    const double t = k * dt;
    const TruthPoint p = traj.at(t);
    ImuSample s;
    s.t_s = t + e.time_offset_s;
    s.gyro_radps = imu_R_cam * p.gyro_cam_radps + bg + e.gyro_noise_radps_rthz * std::sqrt(e.rate_hz) * normal3();
    s.accel_mps2 = imu_R_cam * p.force_cam_mps2 + ba + e.accel_noise_mps2_rthz * std::sqrt(e.rate_hz) * normal3();
    run.samples.push_back(s);
    run.gyro_bias.push_back(bg);
    run.accel_bias.push_back(ba);
    bg += e.gyro_bias_walk_radps_rths * std::sqrt(dt) * normal3();
    ba += e.accel_bias_walk_mps2_rths * std::sqrt(dt) * normal3();
  }
  return run;
}

Eigen::Isometry3d noisy_pose(const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov, std::mt19937_64& rng) {
  std::normal_distribution<double> n01;
  Vector6d z;
  for (int i = 0; i < 6; ++i) z[i] = n01(rng);
  const Matrix6d L = cov.llt().matrixL();
  return geometry::se3_exp(L * z) * cam_T_obj;
}

Matrix6d pose_cov(double sigma_m, double sigma_rad) {
  Matrix6d c = Matrix6d::Zero();
  c.diagonal() << sigma_m * sigma_m, sigma_m * sigma_m, sigma_m * sigma_m, sigma_rad * sigma_rad,
      sigma_rad * sigma_rad, sigma_rad * sigma_rad;
  return c;
}

double chi2_quantile(double p, double dof) {
  const double z = normal_quantile(p), h = 2.0 / (9.0 * dof);
  return dof * std::pow(1 - h + z * std::sqrt(h), 3);
}

}  // namespace epichead::fusion::testing
