#include "epichead/head/head_kinematics.h"

#include <cmath>

namespace epichead::head {

Eigen::Matrix3d tilt_R_cam_nominal() {
  Eigen::Matrix3d R;
  R.col(0) = -Eigen::Vector3d::UnitY();
  R.col(1) = -Eigen::Vector3d::UnitZ();
  R.col(2) = Eigen::Vector3d::UnitX();
  return R;
}

Eigen::Matrix3d tilt_R_cam(const HeadMount& mount) {
  const Eigen::Vector3d& m = mount.cam_misalign_rad;
  return tilt_R_cam_nominal() * (Eigen::AngleAxisd(m.z(), Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(m.y(), Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(m.x(), Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
}

Eigen::Isometry3d body_T_cam(const HeadMount& mount, const JointAngles& q) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translate(mount.pan_origin_body);
  T.rotate(Eigen::AngleAxisd(q.pan_rad, Eigen::Vector3d::UnitZ()));
  T.translate(mount.tilt_origin_pan);
  T.rotate(Eigen::AngleAxisd(q.tilt_rad, Eigen::Vector3d::UnitY()));
  T.translate(mount.cam_offset_tilt);
  T.rotate(tilt_R_cam(mount));
  return T;
}

Eigen::Isometry3d world_T_cam(const Eigen::Isometry3d& world_T_body, const HeadMount& mount, const JointAngles& q) {
  return world_T_body * body_T_cam(mount, q);
}

Eigen::Matrix<double, 3, 2> joint_axes_cam(const HeadMount& mount, const JointAngles& q) {
  // The pan axis is body z (= pan z); the tilt axis is the tilt frame's y. Both expressed in
  // camera axes through the rotations after them in the chain.
  const Eigen::Matrix3d cam_R_tilt = tilt_R_cam(mount).transpose();
  const Eigen::Matrix3d tilt_R_pan = Eigen::AngleAxisd(-q.tilt_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  Eigen::Matrix<double, 3, 2> J;
  J.col(0) = cam_R_tilt * (tilt_R_pan * Eigen::Vector3d::UnitZ());
  J.col(1) = cam_R_tilt * Eigen::Vector3d::UnitY();
  return J;
}

JointAngles aim_joints(const HeadMount& mount, const Eigen::Vector3d& target_body) {
  const Eigen::Vector3d d = target_body - mount.pan_origin_body;
  JointAngles q;
  q.pan_rad = std::atan2(d.y(), d.x());
  const Eigen::Vector3d e = Eigen::AngleAxisd(-q.pan_rad, Eigen::Vector3d::UnitZ()) * d - mount.tilt_origin_pan;
  // +tilt about y turns the forward axis x toward -z, so a target below gives tilt > 0.
  q.tilt_rad = std::atan2(-e.z(), e.x());
  return q;
}

}  // namespace epichead::head
