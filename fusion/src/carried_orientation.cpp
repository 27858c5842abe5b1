#include "epichead/fusion/carried_orientation.h"

#include <algorithm>
#include <cmath>

#include "epichead/fusion/predictor.h"
#include "epichead/geometry/so3.h"

namespace epichead::fusion {

CarriedOrientation::CarriedOrientation(const Eigen::Matrix3d& cam_R_imu, const CarriedOrientationNoise& noise)
    : cam_R_imu_(cam_R_imu), noise_(noise) {}

void CarriedOrientation::set(double t_s, const Eigen::Matrix3d& cam_R_obj, double sigma_rad,
                             const Eigen::Vector3d& gyro_bias_radps) {
  if (!cam_R_obj.allFinite() || !std::isfinite(sigma_rad) || !gyro_bias_radps.allFinite()) return;
  known_ = true;
  cam_R_obj_ = cam_R_obj;
  sigma0_rad_ = sigma_rad;
  bias_radps_ = gyro_bias_radps;
  set_t_s_ = t_s;
  turned_rad_ = 0;
  // Readings from here on turn it; the one at t_s is the start of the next step.
  if (!have_last_ || last_t_s_ < t_s) last_t_s_ = t_s;
}

void CarriedOrientation::set_from(const Predictor& filter, double t_s) {
  const auto& free_axis_obj = filter.options().gravity_check.free_turn_axis_obj;
  const auto p = filter.predict(t_s);
  const auto x = filter.state();
  if (!p || !x) return;
  Eigen::Matrix3d P = p->covariance.bottomRightCorner<3, 3>();  // (translation, rotation): the rotation's
  if (free_axis_obj) {
    // The covariance is of a perturbation in the camera frame: the axis turned there.
    const Eigen::Vector3d a = (p->cam_T_obj.linear() * *free_axis_obj).normalized();
    const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - a * a.transpose();
    P = across * P * across;
  }
  set(t_s, p->cam_T_obj.linear(), std::sqrt(std::max(0.0, P.diagonal().maxCoeff())), x->gyro_bias_radps);
}

void CarriedOrientation::add_gyro(double t_s, const Eigen::Vector3d& gyro_radps) {
  if (!std::isfinite(t_s) || !gyro_radps.allFinite()) return;
  if (have_last_ && t_s <= last_t_s_) return;
  if (known_ && have_last_ && last_t_s_ >= set_t_s_) {
    // The object is static: the camera turning by w (its own frame) turns the object the other
    // way in it. The midpoint reading over the step.
    const double dt = t_s - last_t_s_;
    const Eigen::Vector3d w_cam = cam_R_imu_ * (0.5 * (gyro_radps + last_gyro_) - bias_radps_);
    cam_R_obj_ = geometry::so3_exp(-w_cam * dt) * cam_R_obj_;
    turned_rad_ += w_cam.norm() * dt;
  }
  last_t_s_ = t_s;
  last_gyro_ = gyro_radps;
  have_last_ = true;
}

std::optional<OrientationPrior> CarriedOrientation::at(double t_s) const {
  if (!known_) return std::nullopt;
  const double age_s = std::max(0.0, std::max(t_s, last_t_s_) - set_t_s_);
  const double from_bias = noise_.bias_sigma_radps * age_s;
  const double from_scale = noise_.scale_sigma * turned_rad_;
  return OrientationPrior{cam_R_obj_, std::sqrt(sigma0_rad_ * sigma0_rad_ + from_bias * from_bias + from_scale * from_scale)};
}

}  // namespace epichead::fusion
