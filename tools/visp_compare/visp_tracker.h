#pragma once
// ViSP's vpMbGenericTracker set up for one of our sequences: settings chosen from the image
// size only (never per scene), the camera given as the pinhole of the undistorted image, and a
// per-frame verdict (tracked / lost) with re-initialisation from the last good pose after a loss.
//
// This header and visp_tracker.cpp are the only code that sees ViSP, and they are compiled as
// C++17: ViSP 3.5's headers declare constructors as `vpArray2D<Type>()`, which C++20 forbids.
// So nothing here uses std::expected or includes epichead headers (which need C++23); errors
// come back as a message string instead.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

class vpMbGenericTracker;
template <class Type> class vpImage;

namespace epichead::visp_compare {

enum class TrackerMode { edges, edges_klt };

inline const char* mode_name(TrackerMode mode) { return mode == TrackerMode::edges ? "edges" : "edges+klt"; }

// "3.5.0": the ViSP this program was built against.
std::string visp_version();

// Pinhole intrinsics in pixels (of the undistorted image).
struct Pinhole {
  double fx_px = 0, fy_px = 0, cx_px = 0, cy_px = 0;
};

// Everything we set on the tracker. The reference values are those of ViSP's own teabox
// tutorial (640x480); lengths in pixels scale with the image width. Why each value is what it
// is: docs/visp_compare.md.
struct TrackerSettings {
  // Moving edges (vpMe).
  unsigned me_mask_size = 5;        // oriented gradient mask, pixels
  unsigned me_mask_count = 180;     // orientations of the mask (1 degree steps)
  unsigned me_range_px = 8;         // search distance on each side of the projected edge
  double me_threshold = 10000;      // contrast threshold on the mask response (ViSP 3.5 meaning)
  double me_mu1 = 0.5, me_mu2 = 0.5;  // allowed contrast change between frames
  double me_sample_step_px = 4;     // spacing of the sites along a projected edge
  // KLT points on the visible faces (vpKltOpencv), used in edges+klt mode.
  int klt_max_features = 300;
  int klt_window_px = 5;
  double klt_quality = 0.015;
  double klt_min_distance_px = 8;
  double klt_harris_k = 0.01;
  int klt_block_size_px = 3;
  int klt_pyramid_levels = 3;
  unsigned klt_mask_border_px = 5;  // erosion of the face masks, keeps points off the edges
  // Faces and clipping.
  double angle_appear_deg = 70, angle_disappear_deg = 80;
  double near_clip_m = 0.01;
  // Verdict: a frame is lost when ViSP throws, the pose is not finite or behind the camera,
  // or the projection error (mean angle between image gradient and projected model edge,
  // 0-90 degrees) is above this. Frames that score within 5 cm / 5 deg measured 3-9 deg
  // (p95 up to 11), frames that fail 9-17 deg (docs/visp_compare.md).
  double max_projection_error_deg = 15;
};

TrackerSettings settings_for_image(int width_px, int height_px);

enum class FrameStatus { tracked, lost };

struct FrameResult {
  FrameStatus status = FrameStatus::lost;
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();  // the last good pose when lost
  double projection_error_deg = std::numeric_limits<double>::quiet_NaN();  // NaN when ViSP threw
  unsigned edge_features = 0;       // moving-edge sites used by the pose (ViSP's count)
  unsigned klt_features = 0;        // KLT residual rows used (two per point)
  double track_ms = 0;              // the vpMbGenericTracker::track call alone, wall clock
  double track_cpu_ms = 0;          // the same call, CPU time of this thread (ViSP runs on one
                                    // thread here; on a shared machine wall time includes waits)
  std::string reason;               // why lost; empty when tracked
};

// One image-space feature of the last track() for overlays (undistorted pixel coordinates).
struct DisplayFeature {
  enum class Kind { edge_site_good, edge_site_rejected, klt_point } kind;
  Eigen::Vector2d px;
};

class VispTracker {
 public:
  // Loads the CAO model with ViSP's own loader. pinhole: intrinsics of the undistorted images.
  // Limits ViSP's OpenMP to one thread, so that its cost is per core like epichead's tracker.
  // Returns null and sets `error` ("file: what") when ViSP rejects the model.
  static std::unique_ptr<VispTracker> create(const std::string& cao_path, const Pinhole& pinhole,
                                             TrackerMode mode, const TrackerSettings& settings, std::string& error);
  ~VispTracker();
  VispTracker(const VispTracker&) = delete;
  VispTracker& operator=(const VispTracker&) = delete;

  // Starts tracking on `grey` (8-bit, undistorted) from cam_T_obj, which becomes the last good
  // pose. Returns an empty string, or what went wrong.
  std::string init(const cv::Mat& grey, const Eigen::Isometry3d& cam_T_obj);
  // Tracks one undistorted grey image. After a loss the tracker is re-initialised on this
  // image from the last good pose, as a user of ViSP would do.
  FrameResult track(const cv::Mat& grey);
  // Makes ViSP keep the moving-edge sites and KLT points of each track() (for overlays; off
  // by default since it costs time in the tracking call).
  void keep_display_features();
  // Moving-edge sites and KLT points of the last track(), for the overlay.
  void display_features(std::vector<DisplayFeature>& out);
  unsigned reinitialisations() const { return reinitialisations_; }

 private:
  VispTracker();
  std::unique_ptr<vpMbGenericTracker> tracker_;
  std::unique_ptr<vpImage<unsigned char>> image_;  // reused for every frame
  TrackerSettings settings_;
  Eigen::Isometry3d last_good_cam_T_obj_ = Eigen::Isometry3d::Identity();
  unsigned reinitialisations_ = 0;
};

}  // namespace epichead::visp_compare
