#pragma once
// What `detect`, `track` and `run` share to find the object without a starting pose: the
// detector's command-line options, building its templates with progress on stderr, and the
// gravity direction in the camera frame from a sequence's IMU samples.
#include <expected>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/detector.h"
#include "epichead/vision/offline/sequence.h"

namespace CLI { class App; }

namespace epichead::tools {

struct DetectionArgs {
  vision::DetectorOptions options;
  std::string cache_dir = vision::default_template_cache_dir();
  bool no_cache = false;
  std::string object_up;  // "x,y,z" in the model's frame, or empty
};

// Adds --cache-dir, --no-cache, --object-up, --distance-m, --views, --min-support to `app`.
void add_detection_options(CLI::App& app, DetectionArgs& args);

// Builds (or reads from the cache) the detector for a model and camera, printing progress and
// warnings on stderr as "epichead <command>: ...".
std::expected<std::unique_ptr<vision::Detector>, std::string> make_detector(const std::string& command,
                                                                            const vision::CadModel& model,
                                                                            const vision::Camera& camera,
                                                                            const DetectionArgs& args,
                                                                            const vision::ModelTrackerOptions& tracking);

// The object's up (--object-up), normalised, or nothing; an error for a malformed or zero vector.
std::expected<std::optional<Eigen::Vector3d>, std::string> object_up(const DetectionArgs& args);

// The world's up in the camera frame at t_s: the mean specific force of the IMU samples within
// window_s of t_s (the camera frame's accelerometer reads +g upward at rest). Nothing when no
// sample is near or they cancel out.
std::optional<Eigen::Vector3d> up_from_imu(const std::vector<vision::ImuRecord>& imu, double t_s, double window_s = 0.05);

}  // namespace epichead::tools
