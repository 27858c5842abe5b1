// ModelTracker: the whole per-frame loop (visibility, EPIC windows, validation, pose, cue
// update) follows a moving textured cube over clutter, reports its status honestly and
// re-acquires after the object is gone for a while.
#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/model_tracker.h"

using namespace epichead::vision;

namespace {

CadModel cube_model() {
  RawModel raw;
  const double h = 0.05;
  raw.vertices = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}, {-h, -h, h}, {h, -h, h}, {h, h, h}, {-h, h, h}};
  // Counter-clockwise seen from outside.
  raw.face_loops = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  return *build_model(raw, "cube");
}

Camera test_camera() { return Camera(640, 480, {600, 600, 320, 240}); }

Eigen::Isometry3d pose_at(int k) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(-0.45 + 0.004 * k, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(0.6 + 0.006 * k, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.002 * k, -0.001 * k, 0.55);
  return T;
}

// Clutter (random grey bars and lines), then the cube's front faces in three colours, drawn at 4x
// and area-averaged (exact pixel coverage; OpenCV's anti-aliased polygons are biased by about
// half a pixel), then blur and noise.
cv::Mat render(const CadModel& model, const Camera& cam, const Eigen::Isometry3d& cam_T_obj, bool with_object) {
  constexpr int ss = 4;
  cv::Mat img(cam.height_px() * ss, cam.width_px() * ss, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::RNG rng(7);
  for (int i = 0; i < 60; ++i) {
    const cv::Point p(rng.uniform(0, img.cols), rng.uniform(0, img.rows));
    const cv::Scalar c(rng.uniform(20, 235), rng.uniform(20, 235), rng.uniform(20, 235));
    if (i % 2) cv::rectangle(img, p, p + ss * cv::Point(rng.uniform(5, 80), rng.uniform(5, 80)), c, cv::FILLED);
    else cv::line(img, p, p + ss * cv::Point(rng.uniform(-150, 150), rng.uniform(-150, 150)), c, 2 * ss);
  }
  if (with_object) {
    const cv::Scalar colours[6] = {{40, 60, 200}, {40, 60, 200}, {200, 120, 40}, {200, 120, 40}, {60, 190, 60}, {60, 190, 60}};
    for (std::size_t f = 0; f < model.faces.size(); ++f) {
      const ModelFace& face = model.faces[f];
      const Eigen::Vector3d n_cam = cam_T_obj.linear() * face.normal_obj;
      const Eigen::Vector3d p_cam = cam_T_obj * model.vertices[static_cast<std::size_t>(face.vertices[0])];
      if (n_cam.dot(p_cam) >= 0) continue;  // back face
      std::vector<cv::Point> poly;
      for (int v : face.vertices) {
        const Eigen::Vector2d px = cam.project(cam_T_obj * model.vertices[static_cast<std::size_t>(v)]);
        // Pixel centres: low-res x maps to high-res ss (x + 0.5) - 0.5; 1/16 px drawing precision.
        poly.emplace_back(cvRound((ss * (px.x() + 0.5) - 0.5) * 16), cvRound((ss * (px.y() + 0.5) - 0.5) * 16));
      }
      cv::fillConvexPoly(img, poly, colours[f], cv::LINE_8, 4);
    }
  }
  cv::resize(img, img, cv::Size(cam.width_px(), cam.height_px()), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG nrng(11);
  nrng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
  cv::add(img, noise, img, cv::noArray(), CV_8UC3);
  return img;
}

double rotation_error_deg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() * 180.0 / M_PI;
}

Eigen::Isometry3d perturbed(const Eigen::Isometry3d& T) {
  Eigen::Isometry3d P = T;
  P.linear() = Eigen::AngleAxisd(1.0 * M_PI / 180.0, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix() * T.linear();
  P.translation() += Eigen::Vector3d(0.006, -0.006, 0.005);
  return P;
}

}  // namespace

TEST_CASE("every mode follows a moving cube over clutter from a perturbed start") {
  const CadModel model = cube_model();
  const Camera cam = test_camera();
  for (TrackMode mode : {TrackMode::EpicValidation, TrackMode::Epic, TrackMode::Gradient}) {
    CAPTURE(to_string(mode));
    ModelTrackerOptions options;
    options.mode = mode;
    ModelTracker tracker(model, cam, options);
    WindowImage image;
    FrameReport report;
    Eigen::Isometry3d predicted = perturbed(pose_at(0));
    int tracked = 0;
    double worst_t_mm = 0, worst_r_deg = 0;
    for (int k = 0; k < 15; ++k) {
      REQUIRE(image.assign(render(model, cam, pose_at(k), true)));
      tracker.track(image, predicted, report);
      tracked += report.status == TrackStatus::Tracked;
      worst_t_mm = std::max(worst_t_mm, 1e3 * (report.cam_T_obj.translation() - pose_at(k).translation()).norm());
      worst_r_deg = std::max(worst_r_deg, rotation_error_deg(report.cam_T_obj, pose_at(k)));
      predicted = report.cam_T_obj;
      CHECK(report.visible == 9);
      CHECK(report.times.total_ms >= report.times.pose_ms);
    }
    CHECK(tracked == 15);
    CHECK(worst_t_mm < 3.0);
    CHECK(worst_r_deg < 0.5);
    if (mode == TrackMode::EpicValidation) CHECK(report.junctions >= 3);
  }
}

TEST_CASE("the tracker says lost when the object is gone and re-acquired when it returns") {
  const CadModel model = cube_model();
  const Camera cam = test_camera();
  ModelTracker tracker(model, cam);
  WindowImage image;
  FrameReport report;
  const Eigen::Isometry3d pose = pose_at(0);
  REQUIRE(image.assign(render(model, cam, pose, true)));
  tracker.track(image, pose, report);
  REQUIRE(report.status == TrackStatus::Tracked);
  REQUIRE(image.assign(render(model, cam, pose, false)));  // occluded / out of the scene
  for (int k = 0; k < 3; ++k) {
    tracker.track(image, pose, report);
    CHECK(report.status == TrackStatus::Lost);
    CHECK(report.reasons != TrackReason::None);
    CHECK(report.cam_T_obj.isApprox(pose));  // the prediction is echoed, not a made-up pose
  }
  REQUIRE(image.assign(render(model, cam, pose, true)));
  tracker.track(image, pose, report);
  CHECK(report.status == TrackStatus::Tracked);
  CHECK(has(report.reasons, TrackReason::Reacquired));
  CHECK(rotation_error_deg(report.cam_T_obj, pose) < 0.5);
}

TEST_CASE("reasons print as a readable list") {
  CHECK(to_string(TrackReason::None).empty());
  CHECK(to_string(TrackReason::FewFeatures | TrackReason::PoseFailed) == "few_features+pose_failed");
  CHECK(std::string(to_string(TrackStatus::Degraded)) == "degraded");
}
