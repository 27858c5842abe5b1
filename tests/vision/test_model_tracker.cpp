// ModelTracker: the whole per-frame loop (visibility, EPIC windows, validation, pose, cue
// update) follows a moving textured cube over clutter, reports its status honestly and
// re-acquires after the object is gone for a while.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

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

TEST_CASE("a frame converted tile by tile on demand tracks bit for bit as the whole frame converted") {
  // Every reader of the window image must ask for the pixels it reads (window_image.h): one that
  // did not would read the previous frame's values, or zeros, and its pose would differ.
  const CadModel model = cube_model();
  const Camera cam = test_camera();
  for (TrackMode mode : {TrackMode::EpicValidation, TrackMode::Epic, TrackMode::Gradient}) {
    CAPTURE(to_string(mode));
    ModelTrackerOptions options;
    options.mode = mode;
    ModelTracker on_demand(model, cam, options), whole(model, cam, options);
    WindowImage lazy_image, whole_image;
    FrameReport lazy_report, whole_report;
    Eigen::Isometry3d predicted = perturbed(pose_at(0));
    for (int k = 0; k < 6; ++k) {
      const cv::Mat frame = render(model, cam, pose_at(2 * k), true);
      REQUIRE(lazy_image.assign(frame));
      REQUIRE(whole_image.assign(frame));
      whole_image.prepare_all();
      on_demand.track(lazy_image, predicted, lazy_report);
      whole.track(whole_image, predicted, whole_report);
      CAPTURE(k);
      CHECK(lazy_report.status == whole_report.status);
      CHECK(lazy_report.cam_T_obj.matrix() == whole_report.cam_T_obj.matrix());
      CHECK(lazy_report.covariance == whole_report.covariance);
      CHECK(lazy_image.tiles_prepared() < lazy_image.tiles() / 2);  // the cube covers a small part of the frame
      predicted = lazy_report.cam_T_obj;
    }
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

namespace {

// The cube with a disc printed on the face most towards the camera at pose_at(0): a model
// circle, tracked as an ellipse by the full tracker.
CadModel cube_with_disc(Eigen::Vector3d& disc_centre, Eigen::Vector3d& disc_normal, double& disc_radius) {
  RawModel raw;
  const double h = 0.05;
  raw.vertices = {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}, {-h, -h, h}, {h, -h, h}, {h, h, h}, {-h, h, h}};
  raw.face_loops = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {2, 3, 7, 6}, {1, 2, 6, 5}, {0, 4, 7, 3}};
  const CadModel plain = *build_model(raw, "cube");
  double best = 0;
  for (const ModelFace& f : plain.faces) {
    const Eigen::Vector3d p = plain.vertices[static_cast<std::size_t>(f.vertices[0])];
    const double towards = -(pose_at(0).linear() * f.normal_obj).dot((pose_at(0) * p).normalized());
    if (towards > best) {
      best = towards;
      disc_normal = f.normal_obj;
    }
  }
  disc_centre = h * disc_normal;
  disc_radius = 0.03;
  raw.circles.push_back({disc_centre, disc_normal, disc_radius});
  return *build_model(raw, "cube with disc");
}

// Draws a filled model-space circle and, when board_x_px is finite, a grey board covering every
// pixel right of it, over a rendered frame (at the frame's own resolution, blurred like it).
cv::Mat with_disc_and_board(cv::Mat img, const Camera& cam, const Eigen::Isometry3d& cam_T_obj,
                            const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, double board_x_px) {
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  std::vector<cv::Point> poly;
  for (int i = 0; i < 128; ++i) {
    const double a = 2 * M_PI * i / 128;
    const Eigen::Vector2d px = cam.project(cam_T_obj * (centre + radius * (std::cos(a) * u + std::sin(a) * v)));
    poly.emplace_back(cvRound(px.x() * 16), cvRound(px.y() * 16));
  }
  cv::fillPoly(img, std::vector<std::vector<cv::Point>>{poly}, cv::Scalar(235, 235, 235), cv::LINE_AA, 4);
  if (std::isfinite(board_x_px))
    cv::rectangle(img, cv::Point(static_cast<int>(board_x_px), 0), cv::Point(img.cols, img.rows), cv::Scalar(110, 110, 110), cv::FILLED);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.7);
  return img;
}

// Three frames in full view, six with a board over the right third of the disc's image (the
// cube's edges left of it stay in view), then up to ten without the board; the camera moves
// as in the cube tests. What the full tracker did with the circle, frame by frame.
struct CoveredDiscRun {
  double worst_rotation_deg = 0, worst_translation_mm = 0;
  int full_before = 0;            // of the 3 frames before the board, the ellipse found all round
  bool arc_seen = false;          // under the board, the ellipse found as an arc
  int arc_lines_under_board = 0;  // arc lines placed more than 3 px onto the board
  int occlusions = 0, recoveries = 0;
  int frames_to_full = -1;        // after the board left, frames until the ellipse was whole again
};

CoveredDiscRun run_covered_disc() {
  Eigen::Vector3d centre, normal;
  double radius = 0;
  const CadModel model = cube_with_disc(centre, normal, radius);
  REQUIRE(model.circles.size() == 1u);
  const Camera cam = test_camera();
  ModelTracker tracker(model, cam);
  WindowImage image;
  FrameReport report;
  const Eigen::Vector2d disc_px = cam.project(pose_at(0) * centre);
  const double disc_width_px = 2 * radius * cam.intrinsics().fx_px / (pose_at(0) * centre).z();
  const double board_x_px = disc_px.x() + disc_width_px / 6;
  CoveredDiscRun run;
  Eigen::Isometry3d predicted = pose_at(0);
  int k = 0;
  auto step = [&](bool board) -> const EllipseFeature& {
    const Eigen::Isometry3d truth = pose_at(k++);
    REQUIRE(image.assign(with_disc_and_board(render(model, cam, truth, true), cam, truth, centre, normal, radius,
                                             board ? board_x_px : std::numeric_limits<double>::infinity())));
    tracker.track(image, predicted, report);
    predicted = report.cam_T_obj;
    run.worst_rotation_deg = std::max(run.worst_rotation_deg, rotation_error_deg(report.cam_T_obj, truth));
    run.worst_translation_mm = std::max(run.worst_translation_mm, 1e3 * (report.cam_T_obj.translation() - truth.translation()).norm());
    REQUIRE(tracker.ellipses().features().size() == 1u);
    return tracker.ellipses().features().front();
  };
  for (int i = 0; i < 3; ++i) run.full_before += step(false).arc.full() && report.ellipses_found == 1;
  for (int i = 0; i < 6; ++i) {
    const EllipseFeature& f = step(true);
    if (!f.found || f.arc.full()) continue;
    run.arc_seen = true;
    for (int r = f.arc_row_begin; r < f.arc_row_end; ++r) run.arc_lines_under_board += f.lines[r].centre_px.x() > board_x_px + 3.0;
  }
  for (int i = 0; i < 10 && run.frames_to_full < 0; ++i)
    if (step(false).arc.full()) run.frames_to_full = i + 1;
  run.occlusions = tracker.ellipses().features().front().occlusions;
  run.recoveries = tracker.ellipses().features().front().recoveries;
  return run;
}

}  // namespace

TEST_CASE("the full tracker keeps tracking while a board covers part of a circle, seen as an arc") {
  const CoveredDiscRun run = run_covered_disc();
  CHECK(run.full_before == 3);
  CHECK(run.arc_seen);
  CHECK(run.occlusions >= 1);
  CHECK(run.worst_rotation_deg < 1.0);
  CHECK(run.worst_translation_mm < 5.0);
}

// Known gap (issue 19 item 6): EllipseTracker on its own re-spreads the arc's lines onto the part
// in view and grows the arc back within ten frames (test_ellipse_tracker.cpp); inside the full
// tracker, under the board, 11 arc-line placements still land more than 3 px onto the board and
// the arc never grows back into a whole ellipse by itself (no recovery is counted; the ellipse is
// whole again only because it is lost and placed afresh from the projection). The arc's ends are
// kept as polar angles about the fitted centre and applied about the projection's next frame
// (ProjectionOnArc); an arc kept in the model circle's own angle would carry over (branch
// arc-fix, docs/epic.md). Take [!shouldfail] off when fixed.
TEST_CASE("the full tracker places the arc's lines on the part in view and recovers the whole ellipse after", "[!shouldfail]") {
  const CoveredDiscRun run = run_covered_disc();
  CHECK(run.arc_lines_under_board == 0);
  CHECK(run.frames_to_full > 0);
  CHECK(run.recoveries >= 1);
}
