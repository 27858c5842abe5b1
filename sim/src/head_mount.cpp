#include "epichead/sim/head_mount.h"

#include <cmath>

namespace epichead::sim {

HeadSchedule fixed_head(double pan_rad, double tilt_rad) {
  HeadAngles a;
  a.pan_rad = pan_rad;
  a.tilt_rad = tilt_rad;
  return [a](double) { return a; };
}

Eigen::Matrix3d tilt_R_cam_nominal() {
  Eigen::Matrix3d R;
  R.col(0) = -Eigen::Vector3d::UnitY();  // camera x (right) = tilt -y (left)
  R.col(1) = -Eigen::Vector3d::UnitZ();  // camera y (down)  = tilt -z (up)
  R.col(2) = Eigen::Vector3d::UnitX();   // camera z (forward) = tilt x
  return R;
}

Kinematics body_T_cam(const HeadMount& mount, const HeadAngles& angles) {
  Eigen::Isometry3d body_T_pan0 = Eigen::Isometry3d::Identity();
  body_T_pan0.translation() = mount.pan_origin_body;
  Eigen::Isometry3d pan_T_tilt0 = Eigen::Isometry3d::Identity();
  pan_T_tilt0.translation() = mount.tilt_origin_pan;
  Eigen::Isometry3d tilt_T_cam = Eigen::Isometry3d::Identity();
  tilt_T_cam.translation() = mount.cam_offset_tilt;
  const Eigen::Vector3d& m = mount.cam_misalign_rad;
  tilt_T_cam.linear() = tilt_R_cam_nominal() * (Eigen::AngleAxisd(m.z(), Eigen::Vector3d::UnitZ()) *
                                                Eigen::AngleAxisd(m.y(), Eigen::Vector3d::UnitY()) *
                                                Eigen::AngleAxisd(m.x(), Eigen::Vector3d::UnitX()))
                                                   .toRotationMatrix();
  Kinematics k = fixed_motion(body_T_pan0);
  k = compose(k, rotation_about(Eigen::Vector3d::UnitZ(), angles.pan_rad, angles.pan_rate_radps, angles.pan_accel_radps2));
  k = compose(k, fixed_motion(pan_T_tilt0));
  k = compose(k, rotation_about(Eigen::Vector3d::UnitY(), angles.tilt_rad, angles.tilt_rate_radps, angles.tilt_accel_radps2));
  return compose(k, fixed_motion(tilt_T_cam));
}

HeadAngles aim_at(const HeadMount& mount, const Eigen::Isometry3d& world_T_body, const Eigen::Vector3d& target_world) {
  const Eigen::Vector3d d = world_T_body.inverse() * target_world - mount.pan_origin_body;
  HeadAngles a;
  a.pan_rad = std::atan2(d.y(), d.x());
  const Eigen::Vector3d e = Eigen::AngleAxisd(-a.pan_rad, Eigen::Vector3d::UnitZ()) * d - mount.tilt_origin_pan;
  // Rotating +tilt about y turns the forward axis x toward -z, so a target below has tilt > 0.
  a.tilt_rad = std::atan2(-e.z(), e.x());
  return a;
}

}  // namespace epichead::sim
