#include "image_motion.h"

#include <algorithm>
#include <chrono>

#include "percentile.h"
#include "epichead/geometry/so3.h"
#include "epichead/vision/model_centre.h"
#include "epichead/vision/pose_estimator.h"

namespace epichead::tools {

ImageMotion::ImageMotion(const vision::CadModel& model, const vision::Camera& camera, const ImageMotionOptions& options)
    : camera_(&camera), options_(options), outline_(vision::outline_points(model)), centre_obj_(vision::model_centre(model)) {
}

std::optional<cv::Rect> ImageMotion::region_at(const Eigen::Isometry3d& cam_T_obj) const {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const Eigen::Vector3d& p : outline_) {
    const Eigen::Vector3d q = cam_T_obj * p;
    if (!(q.z() > 1e-3)) return std::nullopt;
    const Eigen::Vector2d px = camera_->project(q);
    x0 = std::min(x0, px.x());
    y0 = std::min(y0, px.y());
    x1 = std::max(x1, px.x());
    y1 = std::max(y1, px.y());
  }
  if (!(x1 > x0 && y1 > y0)) return std::nullopt;
  // A margin of a quarter of the object's size: the region holds the object's outline and some
  // of its surroundings, which move with it under a camera turn.
  const double mx = 0.25 * (x1 - x0), my = 0.25 * (y1 - y0);
  const cv::Rect region = cv::Rect(cv::Rect2d(x0 - mx, y0 - my, x1 - x0 + 2 * mx, y1 - y0 + 2 * my)) &
                          cv::Rect(0, 0, camera_->width_px(), camera_->height_px());
  if (region.area() <= 0) return std::nullopt;
  return region;
}

std::optional<Eigen::Vector2d> ImageMotion::centre_px(const Eigen::Isometry3d& cam_T_obj) const {
  const Eigen::Vector3d c = cam_T_obj * centre_obj_;
  if (!(c.z() > 1e-3)) return std::nullopt;
  return camera_->project(c);
}

Eigen::Isometry3d ImageMotion::turned(const Eigen::Isometry3d& cam_T_obj, const Eigen::Vector2d& from_px) const {
  // The camera turn that moves the ray through from_px onto the seen centre's: applied on the
  // left of cam_T_obj (the camera's motion acts there), it rotates the object about the camera.
  const Eigen::Vector3d from = camera_->unproject(from_px).normalized();
  const Eigen::Vector3d to = camera_->unproject(*seen_px_).normalized();
  Eigen::Isometry3d turn = Eigen::Isometry3d::Identity();
  turn.linear() = geometry::rotation_between(from, to);
  return turn * cam_T_obj;
}

void ImageMotion::measure(const cv::Mat& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::optional<cv::Rect> region = previous_ ? region_at(*previous_) : std::nullopt;
  const auto shift = shifts_.push(frame, region.value_or(cv::Rect()));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  frame_ = nullptr;
  seen_px_.reset();
  if (!region || !shift) return;
  ++measured_;
  ms_.push_back(ms);
  frame_ = {{"shift_px", {shift->shift_px.x(), shift->shift_px.y()}}, {"response", shift->response}, {"ms", ms}};
  const auto previous_px = centre_px(*previous_);
  if (!(shift->response >= options_.min_response) || !previous_px) return;
  seen_px_ = *previous_px + shift->shift_px;
}

std::optional<Eigen::Isometry3d> ImageMotion::seen() const {
  if (!seen_px_) return std::nullopt;
  return turned(*previous_, *centre_px(*previous_));
}

std::optional<Eigen::Isometry3d> ImageMotion::correct(const Eigen::Isometry3d& predicted) {
  if (!seen_px_) return std::nullopt;
  const auto predicted_px = centre_px(predicted);
  if (!predicted_px) return std::nullopt;
  const double gap_px = (*seen_px_ - *predicted_px).norm();
  frame_["predict_gap_px"] = gap_px;
  if (!(gap_px > options_.predict_gap_px)) return std::nullopt;
  ++corrected_;
  frame_["corrected"] = true;
  return turned(predicted, *predicted_px);
}

bool ImageMotion::disagrees(const Eigen::Isometry3d& cam_T_obj, const char* key) {
  const auto px = centre_px(cam_T_obj);
  if (!px) return true;  // behind the camera: nothing like where the image shows the object
  const double gap_px = (*px - *seen_px_).norm();
  frame_[key] = gap_px;
  return gap_px > options_.lock_gap_px;
}

bool ImageMotion::check(vision::ModelTracker& tracker, const vision::WindowImage& image, vision::FrameReport& report) {
  using vision::TrackStatus;
  if (!seen_px_ || report.status == TrackStatus::Lost || !disagrees(report.cam_T_obj, "tracked_gap_px")) return false;
  ++disagreed_;
  const Eigen::Isometry3d from = *seen();
  const vision::StageTimes first = report.times;  // the frame's time is both measurements'
  tracker.reset();
  tracker.track(image, from, report);
  report.times.add_stages(first);
  report.times.total_ms += first.total_ms;
  if (report.status == TrackStatus::Lost || disagrees(report.cam_T_obj, "remeasured_gap_px")) {
    // Nothing the image supports lies where it shows the object (a blurred frame): the turn it
    // measured is the estimate, as loose as a start's, and the tracker starts the next frame
    // afresh from it.
    tracker.reset();
    report.cam_T_obj = from;
    report.covariance = vision::initial_pose_covariance();
    ++replaced_;
    frame_["replaced"] = true;
  }
  // Doubtful either way: no motion is extrapolated from it, and the schedule rechecks it.
  report.status = TrackStatus::Degraded;
  report.reasons = report.reasons | vision::TrackReason::AgainstImageMotion;
  return true;
}

nlohmann::json ImageMotion::to_json() const {
  return {{"measured_frames", measured_},
          {"corrected_predictions", corrected_},
          {"disagreeing_locks", disagreed_},
          {"replaced_by_image_motion", replaced_},
          {"ms_median", percentile(ms_, 0.5)},
          {"ms_p99", percentile(ms_, 0.99)}};
}

}  // namespace epichead::tools
