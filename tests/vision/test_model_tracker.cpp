// ModelTracker: the whole per-frame loop (visibility, EPIC windows, validation, pose, cue
// update) follows a moving textured cube over clutter, reports its status honestly and
// re-acquires after the object is gone for a while.
#include <catch2/catch.hpp>

#include <algorithm>
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

namespace {

// A lamp shade as the simulator's is modelled (a cone of 36 facets, its two rims as circles),
// seen from 35 deg above at 0.6 m.
constexpr int kShadeFacets = 36;
constexpr double kShadeBottomRadius = 0.12, kShadeTopRadius = 0.07, kShadeHeight = 0.16;

CadModel lamp_shade() {
  RawModel raw;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < kShadeFacets; ++i) {
      const double a = 2 * M_PI * i / kShadeFacets, r = ring == 0 ? kShadeBottomRadius : kShadeTopRadius;
      raw.vertices.push_back({r * std::cos(a), r * std::sin(a), ring == 0 ? 0.0 : kShadeHeight});
    }
  for (int i = 0; i < kShadeFacets; ++i) {
    const int j = (i + 1) % kShadeFacets;
    raw.face_loops.push_back({i, j, kShadeFacets + j, kShadeFacets + i});
  }
  raw.circles.push_back({Eigen::Vector3d::Zero(), -Eigen::Vector3d::UnitZ(), kShadeBottomRadius});
  raw.circles.push_back({Eigen::Vector3d(0, 0, kShadeHeight), Eigen::Vector3d::UnitZ(), kShadeTopRadius});
  return *build_model(raw, "lamp shade");
}

Eigen::Isometry3d shade_pose() {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(125 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  p.translation() = Eigen::Vector3d(0.01, 0.06, 0.6);
  return p;
}

// The shade drawn smooth (its inside, seen through the top, darker than its outside) on a dark
// background, then a board of the background's grey over its lower part (the bottom rim) and its
// right side (the right silhouette and the top rim's lower right quarter): what is left in view
// is most of the top rim and the left silhouette. The board's edges lie well away from the
// hidden silhouette, so that no window takes them for it.
cv::Mat shade_behind_board(const CadModel& shade, const Camera& cam, const Eigen::Isometry3d& cam_T_obj) {
  constexpr int ss = 4;
  cv::Mat img(cam.height_px() * ss, cam.width_px() * ss, CV_8UC3, cv::Scalar(60, 60, 60));
  auto poly_of = [&](const ModelFace& f) {
    std::vector<cv::Point> poly;
    for (int v : f.vertices) {
      const Eigen::Vector2d px = cam.project(cam_T_obj * shade.vertices[static_cast<std::size_t>(v)]);
      poly.emplace_back(cvRound((ss * (px.x() + 0.5) - 0.5) * 16), cvRound((ss * (px.y() + 0.5) - 0.5) * 16));
    }
    return poly;
  };
  for (int pass = 0; pass < 2; ++pass)  // the inside (back faces) first, the outside over it
    for (const ModelFace& f : shade.faces) {
      const Eigen::Vector3d n_cam = cam_T_obj.linear() * f.normal_obj;
      const bool front = n_cam.dot(cam_T_obj * shade.vertices[static_cast<std::size_t>(f.vertices[0])]) < 0;
      if (front != (pass == 1)) continue;
      cv::fillConvexPoly(img, poly_of(f), front ? cv::Scalar(200, 205, 210) : cv::Scalar(120, 125, 130), cv::LINE_8, 4);
    }
  const Eigen::Vector2d top = cam.project(cam_T_obj * Eigen::Vector3d(0, 0, kShadeHeight));
  const Eigen::Vector2d bottom = cam.project(cam_T_obj * Eigen::Vector3d::Zero());
  double below_top_rim_px = 0, right_of_top_rim_px = 0;  // the top rim's lowest and rightmost points
  for (int k = 0; k < 72; ++k) {
    const double a = 2 * M_PI * k / 72;
    const Eigen::Vector2d p = cam.project(cam_T_obj * Eigen::Vector3d(kShadeTopRadius * std::cos(a), kShadeTopRadius * std::sin(a), kShadeHeight));
    below_top_rim_px = std::max(below_top_rim_px, p.y() + 4);
    right_of_top_rim_px = std::max(right_of_top_rim_px, p.x() + 2);
  }
  const double above_bottom_rim_px = bottom.y() - 0.35 * (bottom.y() - top.y());
  const cv::Scalar board(60, 60, 60);
  cv::rectangle(img, cv::Point(0, ss * static_cast<int>(above_bottom_rim_px)), cv::Point(img.cols, img.rows), board, cv::FILLED);
  cv::rectangle(img, cv::Point(ss * static_cast<int>(top.x()), ss * static_cast<int>(below_top_rim_px)), cv::Point(img.cols, img.rows),
                board, cv::FILLED);
  cv::rectangle(img, cv::Point(ss * static_cast<int>(top.x() + 0.5 * (right_of_top_rim_px - top.x())), ss * static_cast<int>(top.y())),
                cv::Point(img.cols, img.rows), board, cv::FILLED);
  cv::resize(img, img, cv::Size(cam.width_px(), cam.height_px()), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  return img;
}

}  // namespace

TEST_CASE("a lamp shade with its right side and bottom rim hidden is tracked from its top rim and left silhouette") {
  // A body of revolution with its turn left free has five degrees to fix: one rim and one
  // silhouette do, with a constraint to spare (a pole in front of a lamp shade's side).
  const CadModel shade = lamp_shade();
  const Camera cam = test_camera();
  ModelTracker tracker(shade, cam);
  REQUIRE(tracker.free_turn().has_value());
  const Eigen::Isometry3d truth = shade_pose();
  WindowImage image;
  REQUIRE(image.assign(shade_behind_board(shade, cam, truth)));
  FrameReport report;
  Eigen::Isometry3d start = truth;
  start.translation() += Eigen::Vector3d(0.004, -0.003, 0.004);
  tracker.track(image, start, report);
  INFO("status " << to_string(report.status) << " reasons " << to_string(report.reasons) << " lines " << report.found
                 << " ellipses " << report.ellipses_found);
  CHECK(report.found == 1);
  CHECK(report.ellipses_found == 1);
  REQUIRE(report.status != TrackStatus::Lost);
  CHECK((report.cam_T_obj.translation() - truth.translation()).norm() < 0.003);
  // The axis (what the pose fixes of the turn) within a degree.
  const Eigen::Vector3d axis = tracker.free_turn()->direction_obj;
  CHECK(std::acos(std::clamp((report.cam_T_obj.linear() * axis).dot(truth.linear() * axis), -1.0, 1.0)) < M_PI / 180);
}
