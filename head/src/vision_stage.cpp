#include "vision_stage.h"

#include <chrono>
#include <cstring>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "epichead/geometry/level_to_up.h"
#include "epichead/vision/model_centre.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/revolution_axis.h"

namespace epichead::head {

cv::Mat as_image(const hw::CameraFrame& f, cv::Mat& scratch) {
  auto* data = const_cast<std::uint8_t*>(f.data);  // read only: WindowImage::assign copies out
  const auto stride = static_cast<std::size_t>(f.stride_bytes);
  switch (f.format) {
    case hw::PixelFormat::Gray8: return {f.height, f.width, CV_8UC1, data, stride};
    case hw::PixelFormat::Bgr24: return {f.height, f.width, CV_8UC3, data, stride};
    case hw::PixelFormat::Rgb24: cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC3, data, stride), scratch, cv::COLOR_RGB2BGR); return scratch;
    case hw::PixelFormat::Yuyv: cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC2, data, stride), scratch, cv::COLOR_YUV2BGR_YUYV); return scratch;
    default: return {};
  }
}

VisionStage::VisionStage(const vision::CadModel& model, const vision::Camera& camera,
                         const vision::ModelTrackerOptions& options, VisionThreads threads, double processing_s,
                         const hw::Clock& clock)
    : tracker_(model, camera, options),
      centre_obj_(vision::model_centre(model)),
      threads_(threads),
      processing_s_(processing_s),
      clock_(clock) {
  symmetries_ = vision::model_symmetries(model);
  if (const auto axis = vision::find_revolution_axis(model)) free_axis_obj_ = axis->direction_obj.normalized();
}

VisionStage::~VisionStage() { stop(); }

void VisionStage::start(const std::function<void()>& on_start) {
  if (threads_ != VisionThreads::Thread || worker_.joinable()) return;
  stop_.store(false, std::memory_order_relaxed);
  worker_ = std::thread([this, on_start] {
    if (on_start) on_start();
    worker_loop();
  });
}

void VisionStage::stop() {
  if (!worker_.joinable()) return;
  stop_.store(true, std::memory_order_release);
  submitted_.fetch_add(1, std::memory_order_release);  // wait() returns only on a change of value
  submitted_.notify_one();
  worker_.join();
}

VisionJob& VisionStage::prepare(const hw::CameraFrame& frame) {
  const std::size_t n = frame.size_bytes;
  if (bytes_.size() < n) bytes_.resize(n);  // the first frame (or a larger one): once
  if (n > 0) std::memcpy(bytes_.data(), frame.data, n);
  job_.frame = frame;
  job_.frame.data = bytes_.data();
  return job_;
}

void VisionStage::track_job() {
  result_.index = job_.index;
  result_.exposure_t_s = job_.exposure_t_s;
  result_.taken_t_s = job_.taken_t_s;
  result_.predicted = job_.predicted;
  result_.report = &report_;
  result_.tracker = &tracker_;
  result_.image = &job_.frame;
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat mat = as_image(job_.frame, converted_);
  result_.readable = !mat.empty() && image_.assign(mat).has_value();
  result_.detection = job_.detect && detector_ != nullptr;
  result_.found = false;
  result_.levelled = false;
  if (result_.readable && result_.detection) detect_job(mat);
  else if (result_.readable) tracker_.track(image_, job_.predicted, job_.fallback ? &*job_.fallback : nullptr, report_);
  result_.track_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Detection (allocates: it runs after a loss, not per frame); found: the tracker starts afresh
// from the detected pose, and its report is the job's result.
void VisionStage::detect_job(const cv::Mat& mat) {
  vision::DetectionPrior prior;
  if (job_.detect_near) prior.near_cam_T_obj = job_.predicted;
  if (job_.orient_like_predicted) prior.orient_like = job_.predicted;
  prior.up_cam = job_.up_cam;
  prior.up_obj = job_.up_obj;
  prior.cam_R_obj = job_.carried_cam_R_obj;
  prior.turn_tolerance_deg = job_.turn_tolerance_deg;
  result_.turned_away = false;
  const auto r = detector_->detect(mat, prior);
  result_.found = r && r->found;
  if (!result_.found) {
    report_.status = vision::TrackStatus::Lost;
    report_.reasons = vision::TrackReason::NotVisible;
    report_.cam_T_obj = job_.predicted;
    return;
  }
  // With the down learnt (the ups given), the found pose is levelled to the measured up before the
  // tracker and the predictor start from it, as `track` does: an outline's refinement can settle a
  // few degrees tilted (the can's label band), and a filter seeded there keeps that tilt.
  Eigen::Isometry3d start = r->best.cam_T_obj;
  if (job_.up_cam && job_.up_obj) {
    start = geometry::level_to_up(start, *job_.up_obj, *job_.up_cam, centre_obj_);
    result_.levelled = true;
  }
  tracker_.reset();
  tracker_.track(image_, start, report_);
  report_.reasons = report_.reasons | vision::TrackReason::Reacquired;
  result_.predicted = start;
  // Found turned as the gyro carried it, the tracker can still turn it onto clutter beside the
  // object (as in `track`, tools/track_acquisition.cpp): then it is not found.
  if (job_.carried_cam_R_obj && report_.status != vision::TrackStatus::Lost &&
      vision::symmetric_turn_rad(report_.cam_T_obj.linear(), *job_.carried_cam_R_obj, symmetries_, free_axis_obj_) * 180 / std::numbers::pi >
          job_.turn_tolerance_deg) {
    result_.found = false;
    result_.turned_away = true;
    tracker_.reset();
    report_.status = vision::TrackStatus::Lost;
    report_.reasons = vision::TrackReason::Reacquired | vision::TrackReason::AgainstCarriedTurn;
    report_.cam_T_obj = job_.predicted;
  }
}

void VisionStage::submit(double now_s) {
  busy_ = true;
  if (threads_ == VisionThreads::Thread) {
    submitted_.fetch_add(1, std::memory_order_release);  // publishes job_ to the worker
    submitted_.notify_one();
    return;
  }
  track_job();
  const double modelled = result_.detection ? detection_processing_s_ : processing_s_;
  result_.done_t_s = processing_s_ >= 0 ? now_s + modelled : clock_.now_s();
}

const VisionResult* VisionStage::poll(double now_s) {
  if (!busy_) return nullptr;
  if (threads_ == VisionThreads::Thread)
    return done_.load(std::memory_order_acquire) == submitted_.load(std::memory_order_relaxed) ? &result_ : nullptr;
  return now_s >= result_.done_t_s ? &result_ : nullptr;
}

void VisionStage::release() { busy_ = false; }

void VisionStage::worker_loop() {
  std::uint64_t seen = 0;
  for (;;) {
    // Sleeps in the kernel (a futex) until a job is posted or stop is asked.
    submitted_.wait(seen, std::memory_order_acquire);
    if (stop_.load(std::memory_order_acquire)) return;
    const std::uint64_t posted = submitted_.load(std::memory_order_acquire);
    if (posted == seen) continue;
    seen = posted;
    track_job();
    result_.done_t_s = 0;  // the loop's clock belongs to the control thread: it stamps the publication
    done_.store(seen, std::memory_order_release);  // publishes result_ to the control thread
  }
}

}  // namespace epichead::head
