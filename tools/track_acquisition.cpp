#include "track_acquisition.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include "pose_json.h"
#include "epichead/geometry/level_to_up.h"
#include "epichead/vision/model_centre.h"

namespace epichead::tools {
namespace {

// --no-reacquire keeps the detected start's rechecks but starts none of its own after a doubtful frame.
RecheckOptions recheck_options(const AcquisitionOptions& o) {
  RecheckOptions r = o.recheck;
  r.after_doubt = r.after_doubt && o.reacquire;
  return r;
}

}  // namespace

TrackAcquisition::TrackAcquisition(const vision::Sequence& seq, const vision::ModelTrackerOptions& tracking,
                                   const AcquisitionOptions& options)
    : seq_(&seq), tracking_(tracking), options_(options), rechecks_due_(recheck_options(options)),
      switch_(options.switching), probation_(options.probation),
      centre_obj_(vision::model_centre(seq.model())) {
  if (auto up = object_up(options.detection); up) up_obj_ = *up;
}

std::expected<std::optional<Eigen::Isometry3d>, std::string> TrackAcquisition::detect(
    const cv::Mat& frame, double t_s, const std::optional<Eigen::Isometry3d>& near,
    const std::optional<Eigen::Isometry3d>& orient_like, const std::optional<Upright>& upright,
    const std::optional<fusion::OrientationPrior>& carried) {
  if (!detector_) {
    auto d = make_detector("track", seq_->model(), seq_->camera(), options_.detection, tracking_);
    if (!d) return std::unexpected(d.error());
    detector_ = std::move(*d);
  }
  vision::DetectionPrior prior;
  prior.near_cam_T_obj = near;
  prior.orient_like = orient_like;
  // The filter's down (the camera's mean acceleration taken off) before the accelerometer's plain
  // mean, which the hand-held bursts that cause losses tilt by several degrees (docs/fusion.md).
  if (upright) {
    prior.up_obj = upright->up_obj;
    prior.up_cam = upright->up_cam;
  } else if (options_.use_imu_gravity && up_obj_) {
    prior.up_obj = up_obj_;
    prior.up_cam = up_from_imu(seq_->imu(), t_s);
  }
  if (carried) {
    prior.cam_R_obj = carried->cam_R_obj;
    prior.turn_tolerance_deg = fusion::carried_turn_tolerance_deg(*carried);
    ++detections_turned_;
  }
  const auto t0 = std::chrono::steady_clock::now();
  auto r = detector_->detect(frame, prior);
  detect_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  ++detections_;
  if (!r) return std::unexpected(r.error());
  last_score_ = r->best.score;
  if (!r->found) return std::optional<Eigen::Isometry3d>{};
  return std::optional<Eigen::Isometry3d>{r->best.cam_T_obj};
}

void TrackAcquisition::took_detected(double t_s) {
  rechecks_due_.found_at(t_s);
  switch_.forget();
  probation_.end();
  before_switch_.reset();
  last_doubt_t_s_ = t_s;
}

std::expected<std::optional<Eigen::Isometry3d>, std::string> TrackAcquisition::find_start(const cv::Mat& frame, int frame_number,
                                                                                          double t_s) {
  ++start_attempts_;
  auto r = detect(frame, t_s, std::nullopt);
  if (r && *r) {
    start_frame_ = frame_number;
    took_detected(t_s);
  }
  return r;
}

bool TrackAcquisition::after_frame(vision::TrackStatus status) {
  if (status != vision::TrackStatus::Lost) {
    lost_run_ = 0;
    in_loss_ = false;
    return false;
  }
  if (!in_loss_) ++losses_;
  in_loss_ = true;
  ++lost_run_;
  return options_.reacquire && lost_run_ >= options_.lost_frames_before_detection;
}

std::expected<std::optional<Eigen::Isometry3d>, std::string> TrackAcquisition::find_again(const cv::Mat& frame,
                                                                                          const vision::WindowImage& image, double t_s,
                                                                                          const Eigen::Isometry3d& predicted,
                                                                                          const TrackPredictor& predictor) {
  const std::optional<Upright> upright = predictor.upright(t_s);
  const std::optional<fusion::OrientationPrior> carried = predictor.carried_orientation(t_s);
  // A prediction that tilts the object away (the filter after an IMU gap, or a lock it took) is
  // no place to look near.
  std::optional<Eigen::Isometry3d> near = predicted;
  if (upright) {
    const Eigen::Vector3d u = predicted.linear() * upright->up_obj;
    if (std::atan2(u.cross(upright->up_cam).norm(), u.dot(upright->up_cam)) > upright->max_tilt_rad) near.reset();
  }
  // Even tilted, the prediction's turn about gravity is the gyro's: of the poses a symmetric model
  // cannot tell apart (a box turned half round about its vertical, upright too), the one turned
  // like it (box_clutter 151 with --object-up took the twin after a loss: 26 %; with this, 96 %).
  // But within a stretch of rechecks the prediction may have restarted from a pose a recheck took
  // that was wrong (box_cover held-out 250 with the IMU: the package half out of view behind the
  // board, 99 deg off): the stretch's own reference, the pose before its doubt, is the one to
  // turn like then.
  const bool in_stretch = orient_ref_ && rechecks_due_.provisional(t_s);
  const Eigen::Isometry3d orient_like = in_stretch ? *orient_ref_ : predicted;
  auto r = detect(frame, t_s, near, orient_like, upright, carried);
  if (r && *r && carried) {
    // Found turned as the gyro carried it, the pose is tracked as the re-acquisition will track it:
    // the tracker can still turn it onto clutter beside the object (held-out late_entry 280: found
    // 2 deg from the carried orientation, then tracked 15 deg and 500 mm off, on the wall).
    if (!trial_) trial_ = std::make_unique<vision::ModelTracker>(seq_->model(), seq_->camera(), tracking_);
    trial_->reset();
    trial_->track(image, levelled(**r, upright), trial_report_);
    if (trial_report_.status != vision::TrackStatus::Lost && predictor.turned_from_carried(t_s, trial_report_.cam_T_obj)) {
      ++found_turned_away_;
      return std::optional<Eigen::Isometry3d>{};
    }
  }
  if (r && *r) {
    ++reacquired_;
    took_detected(t_s);
    // The stretch's rechecks turn their result like that too, not like the pose found: a wrong
    // re-acquisition (box_cover held-out 249 and 250, 92-120 deg off after the board) made the
    // recheck that replaced it choose, of the package's half-turn twins, the one nearer it.
    orient_ref_ = orient_like;
    frames_to_reacquire_.push_back(lost_run_);
    lost_run_ = 0;
    in_loss_ = false;
  }
  return r;
}

Eigen::Isometry3d TrackAcquisition::levelled(const Eigen::Isometry3d& found, const std::optional<Upright>& upright) const {
  if (!upright) return found;
  return geometry::level_to_up(found, upright->up_obj, upright->up_cam, centre_obj_);
}

std::expected<std::optional<Eigen::Isometry3d>, std::string> TrackAcquisition::recheck(const cv::Mat& frame,
                                                                                       const vision::WindowImage& image, double t_s,
                                                                                       const vision::FrameReport& tracked,
                                                                                       const Eigen::Isometry3d& orient_like) {
  ++rechecks_;
  // The whole search; of the poses that draw the same outline, the one turned as orient_like is.
  auto found = detect(frame, t_s, std::nullopt, orient_like);
  if (!found) return found;
  const auto now = detector_->verify(frame, tracked.cam_T_obj);
  if (!now) return std::unexpected(now.error());
  const unsigned refused = vision::failed_detection_tests(*now, options_.detection.options) & ~vision::kTooShortOutline;
  RecheckEvidence e{.found = found->has_value(), .found_score = last_score_, .tracked_score = now->score,
                    .tracked_refused = refused != 0, .tracked_lines = tracked.inliers};
  nlohmann::json log = {{"t_s", t_s}, {"found", e.found}, {"found_score", e.found_score}, {"tracked_score", e.tracked_score},
                        {"tracked_support", now->support}, {"tracked_refused", e.tracked_refused},
                        {"tracked_lines", {tracked.inliers, tracked.visible}}, {"tracked_pose", pose_json(tracked.cam_T_obj)}};
  if (e.found) {
    // The tracker's own measurement from the found pose, as a switch would take it (before the
    // switch levels it to gravity).
    if (!trial_) trial_ = std::make_unique<vision::ModelTracker>(seq_->model(), seq_->camera(), tracking_);
    trial_->reset();
    trial_->track(image, **found, trial_report_);
    e.found_lines = trial_report_.inliers;
    const Eigen::AngleAxisd turn(tracked.cam_T_obj.linear().transpose() * (*found)->linear());
    log["found_lines"] = {trial_report_.inliers, trial_report_.visible};
    log["found_status"] = vision::to_string(trial_report_.status);
    log["found_pose"] = pose_json(**found);
    log["turn_deg"] = turn.angle() * 180 / std::numbers::pi;
  }
  const bool take = switch_.take(t_s, e);
  log["switched"] = take;
  recheck_log_.push_back(std::move(log));
  if (!take) return std::optional<Eigen::Isometry3d>{};
  ++switches_;
  took_detected(t_s);
  // The next rechecks keep turning like the stretch's reference (the pose before the doubt, or
  // the prediction a re-acquisition searched from), not like this pose: when it is wrong (the
  // package half out of view behind the board, box_cover held-out 250), of the package's half-turn
  // twins the one nearer it is the wrong one as often as not.
  return found;
}

std::expected<void, std::string> TrackAcquisition::after_tracking(const cv::Mat& frame, const vision::WindowImage& image,
                                                                  double t_s, const Eigen::Isometry3d& predicted,
                                                                  vision::ModelTracker& tracker, TrackPredictor& predictor,
                                                                  vision::FrameReport& report) {
  std::optional<Eigen::Isometry3d> found;
  bool switched = false;
  // A lost frame is a doubtful one too, so the frame kept after it needs no mark of its own here.
  const bool relocked = vision::has(report.reasons, vision::TrackReason::Reacquired);
  if (report.status != vision::TrackStatus::Tracked || relocked) last_doubt_t_s_ = t_s;
  const double lock_since_s = last_doubt_t_s_;  // with `switched`: since when the replaced pose may have been held
  const int doubt_stretches = rechecks_due_.started_after_doubt();
  const bool due = rechecks_due_.due_after(report.status, t_s, relocked);  // never on a lost frame
  if (after_frame(report.status)) {
    auto again = find_again(frame, image, t_s, predicted, predictor);
    if (!again) return std::unexpected(again.error());
    found = *again;
  } else {
    // A stretch a doubtful frame started (degraded, or re-locked from the prediction after a
    // loss: Reacquired without a detection): the tracked pose may be a wrong lock turned well away,
    // and of a symmetric model's outlines the one nearest it may be a twin of the object's. The
    // last pose tracked before it is the one to turn like (with the detected start's, the
    // tracked pose itself).
    if (rechecks_due_.started_after_doubt() != doubt_stretches) orient_ref_ = last_tracked_;
    if (due) {
      auto better = recheck(frame, image, t_s, report, orient_ref_ ? *orient_ref_ : report.cam_T_obj);
      if (!better) return std::unexpected(better.error());
      found = *better;
      switched = found.has_value();
    }
  }
  if (report.status == vision::TrackStatus::Tracked) last_tracked_ = found ? *found : report.cam_T_obj;
  if (!found) return {};
  // A down first learnt while the tracker held the wrong lock this replaces is the lock's: levelled
  // to it, the object's own pose would be tilted off, taken as against gravity and lost, again
  // after each re-acquisition (late_entry development seed 4 with the IMU: a poster's box held for
  // 50 frames from the start). A down learnt before the lock can have begun is kept: on stumble's
  // development seed 1 with the IMU a switch's detected pose, after the jolt, was itself tilted
  // more than 10 deg from a down learnt in the second before it.
  if (switched) {
    before_switch_ = predictor.clone();
    probation_.begin(t_s);
    predictor.replace_wrong_lock(t_s, *found, lock_since_s);
  }
  // With the IMU and the object's down learnt, the tilt is gravity's, not the outline's.
  if (const auto up = predictor.upright(t_s)) {
    found = levelled(*found, up);
    ++levelled_;
  }
  tracker.reset();
  predictor.restart(t_s, *found);
  tracker.track(image, *found, report);
  report.reasons = report.reasons | vision::TrackReason::Reacquired;
  return {};
}

std::unique_ptr<TrackPredictor> TrackAcquisition::after_verdict(double t_s, std::optional<fusion::VisionVerdict> verdict) {
  const bool gated = verdict == fusion::VisionVerdict::Gated;
  const bool judged = gated || verdict == fusion::VisionVerdict::Applied;
  const SwitchProbation::Decision d = probation_.judge(t_s, judged, gated);
  if (d == SwitchProbation::Decision::None) return nullptr;
  std::unique_ptr<TrackPredictor> before = std::move(before_switch_);
  if (d == SwitchProbation::Decision::Stands) return nullptr;
  ++switches_undone_;
  for (auto it = recheck_log_.rbegin(); it != recheck_log_.rend(); ++it)
    if (it->value("switched", false)) {
      (*it)["undone_t_s"] = t_s;
      break;
    }
  // The filter vouched for the pose tracked before against the one found: the search would find
  // that one again on the next rechecks.
  rechecks_due_.quiet();
  return before;
}

nlohmann::json TrackAcquisition::to_json() const {
  std::vector<double> ms = detect_ms_;
  std::sort(ms.begin(), ms.end());
  nlohmann::json j = {{"start", start_frame_ >= 0 ? nlohmann::json{{"frame", start_frame_}, {"attempts", start_attempts_}}
                                                  : nlohmann::json(nullptr)},
                      {"losses", losses_},
                      {"reacquisitions", reacquired_},
                      {"frames_to_reacquire", frames_to_reacquire_},
                      {"detections", detections_},
                      {"detections_narrowed_to_carried_turn", detections_turned_},
                      {"found_turned_away_from_carried", found_turned_away_},
                      {"rechecks", rechecks_},
                      {"recheck_stretches_after_doubt", rechecks_due_.started_after_doubt()},
                      {"levelled_to_gravity", levelled_},
                      {"switches", switches_},
                      {"switches_undone", switches_undone_},
                      {"recheck_log", recheck_log_},
                      {"detect_ms_median", ms.empty() ? 0.0 : ms[ms.size() / 2]},
                      {"detect_ms_max", ms.empty() ? 0.0 : ms.back()}};
  if (detector_) {
    j["templates"] = detector_->template_count();
    j["template_cache"] = detector_->cache_path();
    j["templates_from_cache"] = detector_->loaded_from_cache();
  }
  return j;
}

}  // namespace epichead::tools
