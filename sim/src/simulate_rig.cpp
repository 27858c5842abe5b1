#include "epichead/sim/rig.h"

#include <numbers>

namespace epichead::sim {

Rig::Rig(Trajectory body, HeadMount mount, HeadSchedule head, const Eigen::Isometry3d& world_T_obj)
    : body_(std::move(body)), mount_(mount), head_(std::move(head)), world_T_obj_(world_T_obj) {}

Rig Rig::from_scenario(const Scenario& s, const Eigen::Vector3d& default_target_world,
                       const Eigen::Isometry3d& world_T_obj) {
  Trajectory body = s.motion == MotionKind::walking  ? Trajectory::walking(s.walking)
                    : s.motion == MotionKind::wheeled ? Trajectory::wheeled(s.wheeled)
                                                      : Trajectory::handheld(s.handheld);
  HeadSchedule head;
  if (s.head_deg) {
    constexpr double deg = std::numbers::pi / 180.0;
    head = fixed_head(s.head_deg->x() * deg, s.head_deg->y() * deg);
  } else {
    const HeadAngles a = aim_at(s.mount, body.at(s.aim_t_s).pose, s.aim_world.value_or(default_target_world));
    head = fixed_head(a.pan_rad, a.tilt_rad);
  }
  return Rig(std::move(body), s.mount, std::move(head), world_T_obj);
}

Kinematics Rig::world_T_cam(double t_s) const {
  return compose(body_.at(t_s), body_T_cam(mount_, head_(t_s)));
}

Eigen::Isometry3d Rig::cam_T_obj(double t_s) const { return world_T_cam(t_s).pose.inverse() * world_T_obj_; }

vision::Camera default_camera() {
  vision::Intrinsics k;
  k.fx_px = k.fy_px = 525.0;
  k.cx_px = 319.5;
  k.cy_px = 239.5;
  return vision::Camera(640, 480, k, {-0.10, 0.04, 0.0004, -0.0003, 0.0});
}

std::expected<vision::Camera, std::string> scenario_camera(const Scenario& s) {
  if (s.camera_path.empty()) return default_camera();
  return vision::Camera::load(s.camera_path);
}

}  // namespace epichead::sim
