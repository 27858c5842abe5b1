#pragma once
// How `epichead track` finds the object without init.csv and after a loss: detection
// (vision/detector.h) on the frame, near the predicted pose first and then over the whole
// view sphere, and the counts report.json gives (losses, re-acquisitions, frames to re-acquire).
// The detector is built on first need, so a run that never loses the object pays nothing.
#include <expected>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "detection_setup.h"
#include "recheck_schedule.h"
#include "recheck_switch.h"
#include "switch_probation.h"
#include "track_prediction.h"
#include "epichead/vision/detector.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/offline/sequence.h"

namespace epichead::tools {

struct AcquisitionOptions {
  DetectionArgs detection;
  bool use_imu_gravity = false;      // gravity from imu.csv narrows the search (with --object-up)
  bool reacquire = true;             // detect after a loss (false: retry from the last pose only)
  int lost_frames_before_detection = 3;
  // While a pose is provisional (recheck_schedule.h: found by detection, or after a doubtful
  // frame: degraded, or re-locked after a loss) the whole search runs again every so often, and a
  // pose that explains a much longer outline than the tracked one takes over (recheck_switch.h).
  // Clutter can hold a box-like outline (a printed rectangle) before the object itself comes into
  // view (late_entry).
  RecheckOptions recheck;
  SwitchOptions switching;
  // With the IMU, a switch is undone when the filter started from it gates most of the first
  // poses after it (switch_probation.h). Without the IMU nothing judges it, and it stands.
  ProbationOptions probation;
};

class TrackAcquisition {
 public:
  TrackAcquisition(const vision::Sequence& seq, const vision::ModelTrackerOptions& tracking, const AcquisitionOptions& options);

  // The start: the pose found in this frame, or nothing (the frame counts as searched).
  std::expected<std::optional<Eigen::Isometry3d>, std::string> find_start(const cv::Mat& frame, int frame_number, double t_s);
  // After each tracked frame: the tracker's status. True when detection should run on this
  // frame (lost for lost_frames_before_detection frames in a row, and re-acquisition on).
  bool after_frame(vision::TrackStatus status);
  // Detection after a loss, near `predicted` first. Counts the re-acquisition when found.
  // With `upright` (the IMU's learnt down) the search keeps upright poses only, and skips the
  // predicted pose when that tilts the object away. With the orientation the gyro carried since
  // the filter last knew it (TrackPredictor::carried_orientation) only poses turned within
  // fusion::carried_turn_tolerance_deg of it are found, and the found pose is tracked once on `image` to
  // see that it stays so: refinement can still turn it onto clutter.
  std::expected<std::optional<Eigen::Isometry3d>, std::string> find_again(const cv::Mat& frame, const vision::WindowImage& image,
                                                                          double t_s, const Eigen::Isometry3d& predicted,
                                                                          const TrackPredictor& predictor);
  // After the frame's tracking step (report): detection when the object has been lost for a few
  // frames (near `predicted` first), and the provisional start's recheck. When either finds a
  // pose, the tracker and the predictor restart from it and the frame is measured again.
  std::expected<void, std::string> after_tracking(const cv::Mat& frame, const vision::WindowImage& image, double t_s,
                                                  const Eigen::Isometry3d& predicted, vision::ModelTracker& tracker,
                                                  TrackPredictor& predictor, vision::FrameReport& report);
  // After the predictor judged this frame's pose (TrackPredictor::observe, verdict): when a switch
  // on probation is undone, the predictor as it was before the switch, for the caller to measure
  // the frame again from; null otherwise. The stretch's rechecks then stop.
  std::unique_ptr<TrackPredictor> after_verdict(double t_s, std::optional<fusion::VisionVerdict> verdict);
  // A recheck (the schedule said so): the whole search on this frame, and the pose to switch to
  // when it explains a much longer outline than `tracked` (this frame's tracking).
  // Of the poses that draw the same outline, the one turned as `orient_like` is taken.
  std::expected<std::optional<Eigen::Isometry3d>, std::string> recheck(const cv::Mat& frame, const vision::WindowImage& image,
                                                                       double t_s, const vision::FrameReport& tracked,
                                                                       const Eigen::Isometry3d& orient_like);
  nlohmann::json to_json() const;

 private:
  std::expected<std::optional<Eigen::Isometry3d>, std::string> detect(const cv::Mat& frame, double t_s,
                                                                      const std::optional<Eigen::Isometry3d>& near,
                                                                      const std::optional<Eigen::Isometry3d>& orient_like = {},
                                                                      const std::optional<Upright>& upright = {},
                                                                      const std::optional<fusion::OrientationPrior>& carried = {});
  // A found pose levelled to the IMU's down (geometry/level_to_up.h), as the tracker takes it.
  Eigen::Isometry3d levelled(const Eigen::Isometry3d& found, const std::optional<Upright>& upright) const;
  // A pose found by detection (start, re-acquisition, switch) is taken at t_s: provisional from
  // now, no lead carried over from rechecks of the pose it replaces, and a new lock's beginning.
  void took_detected(double t_s);
  const vision::Sequence* seq_;
  vision::ModelTrackerOptions tracking_;
  AcquisitionOptions options_;
  std::optional<Eigen::Vector3d> up_obj_;
  std::unique_ptr<vision::Detector> detector_;
  // A recheck's found pose measured by the tracker, as a switch would take it (built on first need).
  std::unique_ptr<vision::ModelTracker> trial_;
  vision::FrameReport trial_report_;
  int start_frame_ = -1, start_attempts_ = 0;
  int lost_run_ = 0, losses_ = 0, reacquired_ = 0, detections_ = 0;
  int detections_turned_ = 0;  // detections narrowed to a carried orientation
  int found_turned_away_ = 0;  // of those, found poses refused: tracked, they turned away from it
  bool in_loss_ = false;
  RecheckSchedule rechecks_due_;
  RecheckSwitch switch_;
  SwitchProbation probation_;
  std::unique_ptr<TrackPredictor> before_switch_;  // while a switch is on probation
  std::optional<Eigen::Isometry3d> last_tracked_;  // the last frame's pose with status Tracked
  // For the rechecks of a stretch a doubtful frame or a re-acquisition started.
  std::optional<Eigen::Isometry3d> orient_ref_;
  // The last time the tracked pose may have changed what it holds: a detection (start,
  // re-acquisition, switch), or a frame lost, degraded or re-locked. A wrong lock a recheck
  // replaces was held since then at the earliest.
  double last_doubt_t_s_ = -INFINITY;
  Eigen::Vector3d centre_obj_;  // vision::model_centre: levelled poses turn about it
  int levelled_ = 0;                                     // found poses levelled to gravity (geometry/level_to_up.h)
  int rechecks_ = 0, switches_ = 0, switches_undone_ = 0;
  double last_score_ = 0;
  nlohmann::json recheck_log_ = nlohmann::json::array();  // of the last detection's best hypothesis
  std::vector<int> frames_to_reacquire_;
  std::vector<double> detect_ms_;
};

}  // namespace epichead::tools
