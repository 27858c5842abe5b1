#pragma once
// The moving camera of a scenario: body trajectory -> pan/tilt head -> camera, and the pose
// of the tracked object in the camera. Needs no renderer, so tests and tools can check
// framing and motion cheaply.
#include <Eigen/Geometry>

#include "epichead/sim/head_mount.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/trajectory.h"
#include "epichead/vision/camera.h"

namespace epichead::sim {

class Rig {
 public:
  Rig(Trajectory body, HeadMount mount, HeadSchedule head, const Eigen::Isometry3d& world_T_obj);
  // The scenario's rig; the head aims at the scenario's aim point, else at `default_target_world`.
  static Rig from_scenario(const Scenario& scenario, const Eigen::Vector3d& default_target_world,
                           const Eigen::Isometry3d& world_T_obj = Eigen::Isometry3d::Identity());

  Kinematics world_T_body(double t_s) const { return body_.at(t_s); }
  Kinematics world_T_cam(double t_s) const;
  Eigen::Isometry3d cam_T_obj(double t_s) const;
  HeadAngles head_angles(double t_s) const { return head_(t_s); }
  const Trajectory& body() const { return body_; }
  // Replaces the head angle function (a controller driving the head).
  void set_head(HeadSchedule head) { head_ = std::move(head); }

 private:
  Trajectory body_;
  HeadMount mount_;
  HeadSchedule head_;
  Eigen::Isometry3d world_T_obj_;
};

// The built-in camera: 640 x 480, about 62 degrees wide, modest barrel distortion.
vision::Camera default_camera();
// The scenario's camera: its camera.yaml, or default_camera().
std::expected<vision::Camera, std::string> scenario_camera(const Scenario& scenario);

}  // namespace epichead::sim
