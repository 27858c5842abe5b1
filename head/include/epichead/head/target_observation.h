#pragma once
// What fixation needs from vision: where the target is, in the camera, at a known time. The
// onboard loop gives either the tracker's pose at the frame's exposure time or the predictor's
// pose at any time; the controller carries the direction to now with the gyro attitude.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"

namespace epichead::head {

struct TargetObservation {
  double t_s = 0;                                        // when the camera saw (or is predicted to see) it
  Eigen::Vector3d target_cam = Eigen::Vector3d::UnitZ();  // target point in camera axes (m); only its direction counts
};

// The object point point_obj (the model origin or centroid) seen from cam_T_obj at t_s.
TargetObservation target_from_pose(double t_s, const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector3d& point_obj);

// Image position of a camera-frame point relative to the principal point (pixels), for the
// centring error in diagnostics; NaN when the point is behind the camera.
Eigen::Vector2d offset_from_centre_px(const vision::Camera& camera, const Eigen::Vector3d& p_cam);

}  // namespace epichead::head
