#pragma once
// The onboard loop's vision stage: one camera frame at a time, from its exposure stamp and the
// pose predicted for that instant to the tracked pose with its covariance. The control thread
// hands it a job (the frame's bytes copied out of the camera's buffer, the prediction) and later
// collects the result; it never waits for the tracking itself.
//
// Two ways to run the same stage (OnboardOptions::threads):
//   Inline   the control thread tracks the frame when it submits the job; the result is published
//            `processing_s` later in the loop's time (the simulator's modelled processing time),
//            or at once when that is negative. Runs are deterministic: the simulator's mode.
//   Thread   a worker thread tracks; the result is published when the control thread finds it
//            done. The hand-off in both directions is one slot with atomic sequence numbers (a
//            bounded lock-free queue of capacity one, since one frame is in flight at a time):
//            the control thread neither locks nor waits. The robot's mode.
// One frame in flight: a frame that arrives while the stage is busy is dropped by the loop (and
// counted), so that the next job is always the newest frame rather than a queued old one.
#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/head/onboard_loop.h"
#include "epichead/hw/camera_port.h"
#include "epichead/hw/clock.h"
#include "epichead/vision/detector.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/window_image.h"

namespace epichead::head {

// What the control thread fills in before submit().
struct VisionJob {
  std::uint64_t index = 0;
  double exposure_t_s = 0, taken_t_s = 0;  // the frame's exposure; when the loop took it
  Eigen::Isometry3d predicted = Eigen::Isometry3d::Identity();
  // The second opinion measured when nothing usable is found from `predicted` (the vision poses
  // extrapolated alone; ModelTracker::track's fallback), or none.
  std::optional<Eigen::Isometry3d> fallback;
  hw::CameraFrame frame;                   // data points into the stage's own copy of the bytes
  // Find the object instead of tracking it (the stage's detector): near `predicted` first when
  // detect_near, else over the whole search. orient_like_predicted: of the poses a symmetric
  // model cannot tell apart, the one turned like `predicted` (also when it is too tilted to
  // search near: its turn about gravity is still the gyro's).
  bool detect = false, detect_near = false, orient_like_predicted = false;
  // The world's up in the camera frame and the object's in its own (both known: the detection
  // keeps only poses that agree with them).
  std::optional<Eigen::Vector3d> up_cam, up_obj;
  // The object's orientation the gyro carried since the filter last knew it (fusion/
  // carried_orientation.h), and how far a found pose may be turned from it: the detection keeps
  // only poses turned so, and refuses one the tracker then turns away.
  std::optional<Eigen::Matrix3d> carried_cam_R_obj;
  double turn_tolerance_deg = 0;
};

// What the stage gives back; valid from poll() until release().
struct VisionResult {
  std::uint64_t index = 0;
  double exposure_t_s = 0, taken_t_s = 0;
  double done_t_s = 0;     // Inline: loop clock when the result is published (modelled); Thread: unset
  double track_ms = 0;     // wall time of the job: the image's conversion and the tracking
  bool readable = true;    // false: a pixel format the tracker cannot read (nothing was tracked)
  Eigen::Isometry3d predicted = Eigen::Isometry3d::Identity();
  const vision::FrameReport* report = nullptr;
  const vision::ModelTracker* tracker = nullptr;
  const hw::CameraFrame* image = nullptr;
  bool detection = false;  // the job was a detection (found: the report is the tracking step from its pose)
  bool found = false;
  bool levelled = false;   // found with the ups known: the pose was levelled to them before tracking
  bool turned_away = false;  // found turned as carried, but tracked turned away from it: not found
};

class VisionStage {
 public:
  // `clock` is read on the control thread only (Inline with processing_s < 0).
  VisionStage(const vision::CadModel& model, const vision::Camera& camera, const vision::ModelTrackerOptions& options,
              VisionThreads threads, double processing_s, const hw::Clock& clock);
  ~VisionStage();
  VisionStage(const VisionStage&) = delete;
  VisionStage& operator=(const VisionStage&) = delete;

  // Starts the worker (Thread); `on_start` runs first on the worker (pinning, priority).
  void start(const std::function<void()>& on_start = {});
  void stop();  // joins the worker after its current frame

  // Control thread. While busy() a new job cannot be given.
  bool busy() const { return busy_; }
  // The job to fill: copies the frame's bytes into the stage (allocating only when a frame is
  // larger than any before) and points job.frame at the copy.
  VisionJob& prepare(const hw::CameraFrame& frame);
  void submit(double now_s);
  // The result when it is published at now_s, else nullptr.
  const VisionResult* poll(double now_s);
  void release();  // done with the result: the stage takes a new job

  double inline_wall_ms() const { return result_.track_ms; }  // Inline: wall time of the last submit's job
  // Detection for jobs marked detect; in Inline mode its result is published
  // detection_processing_s after submission. Set before start().
  void set_detector(vision::Detector* detector, double detection_processing_s) {
    detector_ = detector;
    detection_processing_s_ = detection_processing_s;
  }

 private:
  void track_job();  // the stage's work: the job's frame -> result (either thread)
  void worker_loop();

  void detect_job(const cv::Mat& mat);
  vision::ModelTracker tracker_;
  Eigen::Vector3d centre_obj_;  // vision::model_centre: a levelled detection turns about it
  // For the carried orientation's test (vision::symmetric_turn_rad): the model's symmetries and a
  // body of revolution's axis.
  std::vector<Eigen::Isometry3d> symmetries_;
  std::optional<Eigen::Vector3d> free_axis_obj_;
  vision::Detector* detector_ = nullptr;
  double detection_processing_s_ = 0.3;
  VisionThreads threads_;
  double processing_s_;
  const hw::Clock& clock_;
  std::vector<std::uint8_t> bytes_;
  cv::Mat converted_;  // YUYV / RGB frames converted to BGR (reused)
  vision::WindowImage image_;
  vision::FrameReport report_;
  VisionJob job_;
  VisionResult result_;
  bool busy_ = false;  // control thread: a job submitted and not yet released
  // Thread mode: the job and result slots are handed over by these sequence numbers (a job is
  // posted when submitted_ moves past done_, its result when done_ catches up).
  std::atomic<std::uint64_t> submitted_{0}, done_{0};
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

// A camera buffer as an 8-bit grey or BGR image: wrapped without a copy, or converted into
// `scratch` (sized once) for YUYV and RGB. Empty for formats the tracker cannot read (MJPEG).
cv::Mat as_image(const hw::CameraFrame& f, cv::Mat& scratch);

}  // namespace epichead::head
