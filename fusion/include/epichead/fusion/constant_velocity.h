#pragma once
// The fallback without IMU: a Kalman filter on vision poses alone with a constant twist
// (angular rate in the camera frame, velocity in the object frame) driven by white acceleration.
// The Predictor's filter in Mode::ConstantVelocity, behind the same PoseFilter interface as the
// IMU filter.
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/fusion/pose_filter.h"
#include "epichead/fusion/pose_prediction.h"
#include "epichead/fusion/pose_update.h"

namespace epichead::fusion {

struct ConstantVelocityNoise {
  double accel_mps2_rths = 2.0;      // white linear acceleration density
  double angular_accel_radps2_rths = 5.0;  // white angular acceleration density
  double initial_speed_mps = 1.0;    // 1-sigma of the unknown velocity at initialisation
  double initial_rate_radps = 2.0;   // 1-sigma of the unknown angular rate at initialisation
};

class ConstantVelocityFilter final : public PoseFilter {
 public:
  // Error state: orientation (local), position, velocity, angular rate.
  static constexpr int dim = 12;
  using Covariance = Eigen::Matrix<double, dim, dim>;

  explicit ConstantVelocityFilter(const ConstantVelocityNoise& noise = {}) : noise_(noise) {}

  // Starts at the pose at t_s, at rest with the configured uncertainty of the twist (always true).
  bool initialise(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov) override;
  // Moves the state to t_s (t_s >= update_t_s()) and applies the gated pose update (never empty).
  std::optional<PoseUpdateResult> update(double t_s, const Eigen::Isometry3d& cam_T_obj, const Matrix6d& cov,
                                         double gate_chi2) override;
  // The pose at any t_s, extrapolated with the current twist (never empty).
  std::optional<PosePrediction> predict(double t_s) const override;
  double update_t_s() const override { return t_s_; }
  void reset() override {}  // initialise() sets every member

  const Eigen::Vector3d& obj_v_cam() const { return obj_v_cam_; }
  const Eigen::Vector3d& omega_cam_radps() const { return omega_cam_radps_; }

 private:
  void propagate(double dt_s, Eigen::Matrix3d& obj_R_cam, Eigen::Vector3d& obj_p_cam, Covariance& P) const;

  ConstantVelocityNoise noise_;
  double t_s_ = 0;
  Eigen::Matrix3d obj_R_cam_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d obj_p_cam_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d obj_v_cam_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d omega_cam_radps_ = Eigen::Vector3d::Zero();
  Covariance P_ = Covariance::Identity();
};

}  // namespace epichead::fusion
