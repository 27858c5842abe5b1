#pragma once
// Without the IMU, `epichead track` predicts each frame by constant velocity, which cannot know
// that a burst of camera motion has started: the object jumps 20-60 px between frames and the
// windows miss it, or find clutter. The image itself says where the object's region went
// (vision/region_shift.h), and that is used twice:
// - the prediction: when the place the image shows and the constant-velocity prediction's
//   disagree by more than predict_gap_px, the prediction is turned (a rotation of the camera
//   about its centre, as a gyro would say) to put the object where the image shows it;
// - the check: a tracked pose whose object centre lies more than lock_gap_px from where the
//   image shows it moved has locked onto something else (clutter beside a blurred edge). It is
//   measured again from where the image shows the object, with nothing learnt from the lock;
//   when that disagrees too, the frame's pose is the previous one turned as the image moved.
// The thresholds were set on development seeds 1-8 of box_clutter (docs/detection.md).
#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/region_shift.h"
#include "epichead/vision/window_image.h"

namespace epichead::tools {

struct ImageMotionOptions {
  double predict_gap_px = 8;   // below this the constant-velocity prediction stands
  double lock_gap_px = 10;     // beyond this a tracked pose disagrees with the image's motion
  double min_response = 0.1;   // weaker correlation peaks are not believed
};

class ImageMotion {
 public:
  ImageMotion(const vision::CadModel& model, const vision::Camera& camera, const ImageMotionOptions& options);

  // Before tracking a frame: correlates the region of the model at the last pose given to
  // tracked() with this frame (nothing is measured after a lost frame).
  void measure(const cv::Mat& frame);
  // `predicted` turned to where the image shows the object, when they disagree by more than
  // predict_gap_px; otherwise nothing (the prediction stands).
  std::optional<Eigen::Isometry3d> correct(const Eigen::Isometry3d& predicted);
  // After tracking the frame: when the tracked pose disagrees with the image's motion, the frame
  // is measured again (see above) and `report` says what came of it: reason AgainstImageMotion,
  // status Degraded (a doubtful frame: the recheck schedule's). True when it acted.
  bool check(vision::ModelTracker& tracker, const vision::WindowImage& image, vision::FrameReport& report);
  // After the frame: the pose its region is drawn at next frame, or nothing (lost).
  void tracked(const std::optional<Eigen::Isometry3d>& cam_T_obj) { previous_ = cam_T_obj; }

  // For report.json: totals, and this frame's measurement (null when none was made).
  nlohmann::json to_json() const;
  const nlohmann::json& frame_json() const { return frame_; }

 private:
  // The previous pose turned so that the object's centre lies where the image shows it.
  std::optional<Eigen::Isometry3d> seen() const;
  std::optional<cv::Rect> region_at(const Eigen::Isometry3d& cam_T_obj) const;
  std::optional<Eigen::Vector2d> centre_px(const Eigen::Isometry3d& cam_T_obj) const;
  Eigen::Isometry3d turned(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector2d& from_px) const;
  // True when the pose puts the object's centre more than lock_gap_px from where the image shows it.
  bool disagrees(const Eigen::Isometry3d& cam_T_obj, const char* key);

  const vision::Camera* camera_;
  ImageMotionOptions options_;
  std::vector<Eigen::Vector3d> outline_;
  Eigen::Vector3d centre_obj_;
  vision::RegionShiftEstimator shifts_;
  std::optional<Eigen::Isometry3d> previous_;
  std::optional<Eigen::Vector2d> seen_px_;  // this frame: where the image shows the object's centre
  nlohmann::json frame_;
  std::vector<double> ms_;  // per measured frame: the correlation's time (shrink to grey, DFTs)
  int measured_ = 0, corrected_ = 0, disagreed_ = 0, replaced_ = 0;
};

}  // namespace epichead::tools
