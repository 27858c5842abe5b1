#pragma once
// A sequence directory (DESIGN.md): camera.yaml (or camera.yml, camera_info.yaml), model.cao, frames (frames.csv + images, or
// video.mp4), optional init.csv (without it the object is detected), imu.csv and gt.csv. Real and simulated sequences read alike.
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/offline/stamped_pose.h"

namespace epichead::vision {

// One IMU sample in the camera frame: rad/s and specific force in m/s^2.
struct ImuRecord {
  double t_s = 0;
  Eigen::Vector3d gyro_radps = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_mps2 = Eigen::Vector3d::Zero();
};

struct FrameEntry {
  int frame = 0;
  double t_s = 0;
  std::string file;  // relative to the directory; empty when frames come from video.mp4
};

// The names a sequence's camera calibration may have, the first preferred.
inline constexpr const char* kCameraFileNames[] = {"camera.yaml", "camera.yml", "camera_info.yaml"};

class Sequence {
 public:
  // Reads and checks everything but the images: a malformed row is a file:line error and a
  // missing frame file is reported here, before any work starts.
  static std::expected<Sequence, std::string> open(const std::string& dir);

  const std::string& dir() const { return dir_; }
  const Camera& camera() const { return camera_; }
  const CadModel& model() const { return model_; }
  // The starting pose from init.csv, or one the caller found (set_init); identity at frame -1
  // when there is neither.
  bool has_init() const { return has_init_; }
  const StampedPose& init() const { return init_; }
  void set_init(const StampedPose& pose) { init_ = pose; has_init_ = true; }
  bool has_ground_truth() const { return !gt_.empty(); }
  const std::vector<StampedPose>& ground_truth() const { return gt_; }
  bool has_imu() const { return !imu_.empty(); }
  const std::vector<ImuRecord>& imu() const { return imu_; }
  const std::vector<FrameEntry>& frames() const { return frames_; }
  std::size_t frame_count() const { return frames_.size(); }

  // Decodes frame `index` (0-based position in frames()). Sequential reads of a video are
  // cheap; going backwards re-opens it. A corrupt or unreadable image, or one whose size is not
  // the calibration's, is an error value.
  std::expected<cv::Mat, std::string> read_frame(std::size_t index);

  Sequence(Sequence&&) noexcept;
  Sequence& operator=(Sequence&&) noexcept;
  ~Sequence();

 private:
  Sequence();
  std::string dir_;
  std::string camera_file_;  // the calibration read (one of kCameraFileNames)
  Camera camera_;
  CadModel model_;
  StampedPose init_{-1, 0.0, Eigen::Isometry3d::Identity(), ""};
  bool has_init_ = false;
  std::vector<StampedPose> gt_;
  std::vector<ImuRecord> imu_;
  std::vector<FrameEntry> frames_;
  std::expected<void, std::string> check_size(const cv::Mat& image, const std::string& what) const;
  struct VideoReader;
  std::unique_ptr<VideoReader> video_;
};

std::expected<std::vector<ImuRecord>, std::string> read_imu_csv(const std::string& path);
std::expected<void, std::string> write_imu_csv(const std::string& path, const std::vector<ImuRecord>& samples);
std::expected<std::vector<FrameEntry>, std::string> read_frames_csv(const std::string& path);
std::expected<void, std::string> write_frames_csv(const std::string& path, const std::vector<FrameEntry>& frames);

}  // namespace epichead::vision
