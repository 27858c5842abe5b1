#include "visp_tracker.h"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <iostream>
#include <sstream>
#include <cmath>
#include <limits>
#include <utility>

#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpException.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpConfig.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpImageConvert.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpPolygon3D.h>
#include <visp3/klt/vpKltOpencv.h>
#include <visp3/mbt/vpMbGenericTracker.h>
#include <visp3/me/vpMe.h>
#include <visp3/me/vpMeSite.h>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace epichead::visp_compare {
namespace {

vpHomogeneousMatrix to_visp(const Eigen::Isometry3d& cam_T_obj) {
  vpHomogeneousMatrix m;
  for (unsigned r = 0; r < 3; ++r)
    for (unsigned c = 0; c < 4; ++c) m[r][c] = cam_T_obj.matrix()(r, c);
  return m;
}

Eigen::Isometry3d to_eigen(const vpHomogeneousMatrix& m) {
  Eigen::Matrix3d rotation;
  Eigen::Vector3d translation;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c) rotation(r, c) = m[r][c];
    translation(r) = m[r][3];
  }
  // ViSP keeps R orthonormal to rounding; re-orthonormalise through a quaternion so that the
  // pose CSV (w, x, y, z) is exact.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(rotation).normalized().toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

double thread_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

// ViSP 3.5's CAO loader prints its element counts on std::cout even when not verbose; this
// keeps the program's stdout to its own summary while it runs.
class SilenceStdout {
 public:
  SilenceStdout() : saved_(std::cout.rdbuf(sink_.rdbuf())) {}
  ~SilenceStdout() { std::cout.rdbuf(saved_); }
  SilenceStdout(const SilenceStdout&) = delete;
  SilenceStdout& operator=(const SilenceStdout&) = delete;

 private:
  std::ostringstream sink_;
  std::streambuf* saved_;
};

bool finite_pose(const Eigen::Isometry3d& pose) { return pose.matrix().allFinite(); }

std::string visp_message(const vpException& e) {
  std::string text = e.getStringMessage();
  if (text.empty()) text = e.what();
  return "ViSP: " + text;
}

}  // namespace

std::string visp_version() {
  return std::to_string(VISP_VERSION_MAJOR) + "." + std::to_string(VISP_VERSION_MINOR) + "." +
         std::to_string(VISP_VERSION_PATCH);
}

TrackerSettings settings_for_image(int width_px, int /*height_px*/) {
  // ViSP's teabox tutorial values are for 640 px wide images; distances in pixels scale with
  // the width so that a sequence at another resolution sees the same geometry.
  TrackerSettings s;
  const double scale = width_px / 640.0;
  const auto scaled = [scale](double px) { return std::max(1.0, std::round(px * scale)); };
  s.me_range_px = static_cast<unsigned>(scaled(s.me_range_px));
  s.me_sample_step_px = scaled(s.me_sample_step_px);
  s.klt_min_distance_px = scaled(s.klt_min_distance_px);
  s.klt_max_features = static_cast<int>(std::round(s.klt_max_features * scale * scale));
  s.klt_mask_border_px = static_cast<unsigned>(scaled(s.klt_mask_border_px));
  return s;
}

VispTracker::VispTracker() : image_(std::make_unique<vpImage<unsigned char>>()) {}
VispTracker::~VispTracker() = default;

std::unique_ptr<VispTracker> VispTracker::create(const std::string& cao_path, const Pinhole& pinhole,
                                                 TrackerMode mode, const TrackerSettings& settings,
                                                 std::string& error) {
#ifdef _OPENMP
  omp_set_num_threads(1);
#endif
  std::unique_ptr<VispTracker> owner(new VispTracker());
  VispTracker& t = *owner;
  t.settings_ = settings;
  int type = vpMbGenericTracker::EDGE_TRACKER;
  if (mode == TrackerMode::edges_klt) type |= vpMbGenericTracker::KLT_TRACKER;
  try {
    t.tracker_ = std::make_unique<vpMbGenericTracker>(1u, type);
    {
      SilenceStdout quiet;
      t.tracker_->loadModel(cao_path, /*verbose=*/false);
    }

    vpCameraParameters camera;
    camera.initPersProjWithoutDistortion(pinhole.fx_px, pinhole.fy_px, pinhole.cx_px, pinhole.cy_px);
    t.tracker_->setCameraParameters(camera);

    vpMe me;
    me.setMaskSize(settings.me_mask_size);
    me.setMaskNumber(settings.me_mask_count);
    me.setRange(settings.me_range_px);
    me.setThreshold(settings.me_threshold);
    me.setMu1(settings.me_mu1);
    me.setMu2(settings.me_mu2);
    me.setSampleStep(settings.me_sample_step_px);
    t.tracker_->setMovingEdge(me);

    if (mode == TrackerMode::edges_klt) {
      vpKltOpencv klt;
      klt.setMaxFeatures(settings.klt_max_features);
      klt.setWindowSize(settings.klt_window_px);
      klt.setQuality(settings.klt_quality);
      klt.setMinDistance(settings.klt_min_distance_px);
      klt.setHarrisFreeParameter(settings.klt_harris_k);
      klt.setBlockSize(settings.klt_block_size_px);
      klt.setPyramidLevels(settings.klt_pyramid_levels);
      t.tracker_->setKltOpencv(klt);
      t.tracker_->setKltMaskBorder(settings.klt_mask_border_px);
    }

    t.tracker_->setAngleAppear(vpMath::rad(settings.angle_appear_deg));
    t.tracker_->setAngleDisappear(vpMath::rad(settings.angle_disappear_deg));
    t.tracker_->setNearClippingDistance(settings.near_clip_m);
    // Faces are clipped by the near plane and the field of view, so a model larger than the
    // view (a room corner) still projects to valid lines.
    t.tracker_->setClipping(vpPolygon3D::NEAR_CLIPPING | vpPolygon3D::FOV_CLIPPING);
    // ViSP's default visibility (back-face culling, no scan-line rendering). Scan-line
    // rendering would also hide edges behind other faces of non-convex models, but it made the
    // tracking call about ten times slower on mockup_walk and office_pan (25 -> 250 ms) for no
    // gain in accuracy there (docs/visp_compare.md), so a user would leave it off.
    t.tracker_->setScanLineVisibilityTest(false);
    t.tracker_->setProjectionErrorComputation(true);
    t.tracker_->setDisplayFeatures(false);
  } catch (const vpException& e) {
    error = cao_path + ": " + visp_message(e);
    return nullptr;
  } catch (const std::exception& e) {
    error = cao_path + ": " + e.what();
    return nullptr;
  }
  return owner;
}

std::string VispTracker::init(const cv::Mat& grey, const Eigen::Isometry3d& cam_T_obj) {
  if (!finite_pose(cam_T_obj)) return "initial pose is not finite";
  if (grey.type() != CV_8UC1) return "initialisation: image is not 8-bit grey";
  try {
    vpImageConvert::convert(grey, *image_);
    tracker_->initFromPose(*image_, to_visp(cam_T_obj));
  } catch (const vpException& e) {
    return "initialisation: " + visp_message(e);
  }
  last_good_cam_T_obj_ = cam_T_obj;
  return {};
}

FrameResult VispTracker::track(const cv::Mat& grey) {
  FrameResult result;
  if (grey.type() != CV_8UC1) {
    result.reason = "image is not 8-bit grey";
    result.cam_T_obj = last_good_cam_T_obj_;
    return result;
  }
  vpImageConvert::convert(grey, *image_);
  const vpImage<unsigned char>& image = *image_;
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start_ms = thread_cpu_ms();
  bool threw = false;
  try {
    tracker_->track(image);
  } catch (const vpException& e) {
    threw = true;
    result.reason = visp_message(e);
  } catch (const std::exception& e) {
    threw = true;
    result.reason = std::string("ViSP: ") + e.what();
  }
  result.track_cpu_ms = thread_cpu_ms() - cpu_start_ms;
  result.track_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  result.edge_features = tracker_->getNbFeaturesEdge();
  result.klt_features = tracker_->getNbFeaturesKlt();

  Eigen::Isometry3d cam_T_obj = last_good_cam_T_obj_;
  if (!threw) {
    vpHomogeneousMatrix m;
    tracker_->getPose(m);
    cam_T_obj = to_eigen(m);
    result.projection_error_deg = tracker_->getProjectionError();
    if (!finite_pose(cam_T_obj)) {
      result.reason = "pose is not finite";
    } else if (cam_T_obj.translation().z() <= 0) {
      result.reason = "object origin behind the camera";
    } else if (!(result.projection_error_deg <= settings_.max_projection_error_deg)) {
      result.reason = "projection error " + std::to_string(result.projection_error_deg) + " deg above " +
                      std::to_string(settings_.max_projection_error_deg);
    }
  }
  if (result.reason.empty()) {
    result.status = FrameStatus::tracked;
    result.cam_T_obj = cam_T_obj;
    last_good_cam_T_obj_ = cam_T_obj;
    return result;
  }
  result.status = FrameStatus::lost;
  result.cam_T_obj = last_good_cam_T_obj_;
  ++reinitialisations_;
  try {
    tracker_->initFromPose(image, to_visp(last_good_cam_T_obj_));
  } catch (const vpException& e) {
    result.reason += "; re-initialisation failed: " + visp_message(e);
  }
  return result;
}

void VispTracker::keep_display_features() { tracker_->setDisplayFeatures(true); }

void VispTracker::display_features(std::vector<DisplayFeature>& out) {
  out.clear();
  // ViSP 3.5 layout: moving-edge site {0, i, j, state}, KLT point {1, i, j, i_proj, j_proj, id},
  // with i the row and j the column.
  for (const auto& f : tracker_->getFeaturesForDisplay()) {
    if (f.size() < 3) continue;
    const Eigen::Vector2d px(f[2], f[1]);
    if (f[0] == 0 && f.size() >= 4) {
      const bool good = static_cast<int>(f[3]) == vpMeSite::NO_SUPPRESSION;
      out.push_back({good ? DisplayFeature::Kind::edge_site_good : DisplayFeature::Kind::edge_site_rejected, px});
    } else if (f[0] == 1) {
      out.push_back({DisplayFeature::Kind::klt_point, px});
    }
  }
}

}  // namespace epichead::visp_compare
