// EllipseTracker: tracker lines on a projected ellipse, EPIC on them, the fit, and occlusion
// handling by arcs (break, re-spread, extension lines, growing back, weak arcs).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/tracker_lines.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

Ellipse make(double cx, double cy, double a, double b, double angle) {
  Ellipse e;
  e.centre_px = {cx, cy};
  e.semi_major_px = a;
  e.semi_minor_px = b;
  e.angle_rad = angle;
  return e;
}

// A dark brown disc (the object) on a cluttered background of light random blocks (every
// boundary of the disc has contrast); optionally a light-grey occluder covering x >= occluder_x.
// The disc is rendered by 4x4 supersampling of its implicit equation (exact sub-pixel edge).
cv::Mat frame(const Ellipse& e, double occluder_x, unsigned seed) {
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG blocks(99);  // the same background every frame
  for (int y = 0; y < img.rows; y += 12)
    for (int x = 0; x < img.cols; x += 12) {
      const cv::Scalar c(blocks.uniform(140, 250), blocks.uniform(140, 250), blocks.uniform(140, 250));
      cv::rectangle(img, {x, y}, {x + 11, y + 11}, c, cv::FILLED);
    }
  const Eigen::Vector2d u = e.major_axis(), v = e.minor_axis();
  const cv::Vec3d disc(40, 60, 110);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      int inside = 0;
      for (int i = 0; i < 16; ++i) {
        const Eigen::Vector2d d = Eigen::Vector2d(x - 0.375 + 0.25 * (i % 4), y - 0.375 + 0.25 * (i / 4)) - e.centre_px;
        const double p = d.dot(u) / e.semi_major_px, q = d.dot(v) / e.semi_minor_px;
        inside += p * p + q * q < 1.0;
      }
      if (inside == 0) continue;
      cv::Vec3b& px = img.at<cv::Vec3b>(y, x);
      const double f = inside / 16.0;
      for (int c = 0; c < 3; ++c) px[c] = cv::saturate_cast<uchar>(f * disc[c] + (1 - f) * px[c]);
    }
  if (occluder_x < img.cols)
    cv::rectangle(img, cv::Point(static_cast<int>(occluder_x), 0), cv::Point(img.cols, img.rows), cv::Scalar(200, 205, 210),
                  cv::FILLED);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
  cv::add(img, noise, img, cv::noArray(), CV_8UC3);
  return img;
}

double angle_diff(double a, double b) { return std::fabs(std::remainder(a - b, std::numbers::pi)); }

}  // namespace

TEST_CASE("tracker lines are spread evenly over the contour, normal to it, arcs end on their end points", "[tracker_lines]") {
  const Ellipse e = make(160, 120, 90, 40, 0.3);
  TrackerLine lines[30];
  const double step = spread_tracker_lines(e, EllipseArc{}, 30, lines);
  REQUIRE(step > 0);
  for (int i = 0; i < 30; ++i) {
    const TrackerLine& a = lines[i];
    const TrackerLine& b = lines[(i + 1) % 30];
    CHECK((b.centre_px - a.centre_px).norm() == Approx(step).epsilon(0.03));  // chord ~ arc at 30 lines
    CHECK(e.distance(a.centre_px) < 1e-6);
    CHECK(a.normal.norm() == Approx(1.0));
    CHECK(a.normal.dot(a.centre_px - e.centre_px) > 0);  // outward
  }
  const EllipseArc arc{0.5, 2.0};
  spread_tracker_lines(e, arc, 30, lines);
  CHECK(std::fabs(wrap_angle(lines[0].polar_rad - 0.5)) < 1e-6);
  CHECK(std::fabs(wrap_angle(lines[29].polar_rad - 2.5)) < 1e-6);
  for (int i = 1; i < 30; ++i) CHECK(wrap_angle(lines[i].polar_rad - lines[i - 1].polar_rad) > 0);
  // The extension line lies one spacing beyond the end, on the ellipse.
  const TrackerLine beyond = tracker_line_beyond(e, lines[29].polar_rad, 10.0, +1);
  CHECK((beyond.centre_px - lines[29].centre_px).norm() == Approx(10.0).epsilon(0.05));
  CHECK(wrap_angle(beyond.polar_rad - 2.5) > 0);
}

TEST_CASE("the ellipse tracker follows a moving disc on clutter to sub-pixel accuracy", "[ellipse_tracker]") {
  for (EpicMode mode : {EpicMode::Epic, EpicMode::EpicSingle}) {
    EllipseTrackerOptions options;
    options.mode = mode;
    EllipseTracker tracker(options);
    WindowImage image;
    const Ellipse start = make(150, 115, 70, 45, 0.4);
    for (int k = 0; k < 8; ++k) {
      const Ellipse truth = make(150 + 3.0 * k, 115 + 1.5 * k, 70, 45, 0.4);
      REQUIRE(image.assign(frame(truth, 1e9, 10 + k)));
      tracker.track_one(image, 0, make(152, 117, 70, 45, 0.4) /* 2.8 px off at frame 0 */, WindowPlacement::Previous);
      const EllipseFeature& f = tracker.features().at(0);
      INFO("frame " << k);
      REQUIRE(f.found);
      CHECK(f.arc.full());
      CHECK_FALSE(f.weak);
      CHECK((f.ellipse.centre_px - truth.centre_px).norm() < 0.5);
      CHECK(f.ellipse.semi_major_px == Approx(70).margin(0.6));
      CHECK(f.ellipse.semi_minor_px == Approx(45).margin(0.6));
      CHECK(angle_diff(f.ellipse.angle_rad, 0.4) < 0.03);
      CHECK(f.lines.size() == 30u);
    }
    (void)start;
  }
}

TEST_CASE("a third of the rim occluded is excluded as an arc and recovered when the occluder leaves", "[ellipse_tracker]") {
  EllipseTracker tracker;
  WindowImage image;
  const Ellipse truth = make(150, 120, 80, 55, 0.0);
  const double occluder_x = 150 + 40;  // x >= cx + a/2: one third of the contour's parameter range
  int frame_no = 0;
  auto step = [&](double occ) {
    REQUIRE(image.assign(frame(truth, occ, 100 + frame_no++)));
    tracker.track_one(image, 0, truth, WindowPlacement::Previous);
    return tracker.features().at(0);
  };
  for (int k = 0; k < 2; ++k) CHECK(step(1e9).arc.full());
  // Occluded: the arc breaks within a frame, the lines go to the free two thirds.
  for (int k = 0; k < 6; ++k) {
    const EllipseFeature& f = step(occluder_x);
    INFO("occluded frame " << k);
    REQUIRE(f.found);
    CHECK_FALSE(f.arc.full());
    CHECK(f.arc.span_rad > 200.0 * std::numbers::pi / 180);
    CHECK(f.arc.span_rad < 265.0 * std::numbers::pi / 180);
    CHECK_FALSE(f.weak);
    CHECK((f.ellipse.centre_px - truth.centre_px).norm() < 1.0);
    CHECK(f.ellipse.semi_major_px == Approx(80).margin(1.0));
    // No inlier on the occluder: every inlier edgel lies left of its border.
    for (int q = 0; q < f.inlier_count(); ++q) {
      const auto& c = f.candidates[f.selected];
      CHECK(tracker.edgel_px(f, f.candidate_inliers[c.inlier_begin + q]).x() < occluder_x + 1.0);
    }
    if (k > 0) {
      // Re-spread: all 30 arc lines lie on the free part, two extension lines watch the ends.
      CHECK(f.lines.size() == 32u);
      for (int r = f.arc_row_begin; r < f.arc_row_end; ++r) CHECK(f.lines[r].centre_px.x() < occluder_x + 2.0);
    }
  }
  CHECK(tracker.features().at(0).occlusions >= 1);
  // The occluder leaves: the extension lines find the rim and the arc grows back to the ellipse.
  int frames_to_full = -1;
  for (int k = 0; k < 15 && frames_to_full < 0; ++k)
    if (step(1e9).arc.full()) frames_to_full = k + 1;
  INFO("frames to recover: " << frames_to_full);
  CHECK(frames_to_full > 0);
  CHECK(frames_to_full <= 10);
  CHECK(tracker.features().at(0).recoveries >= 1);
  const EllipseFeature& f = step(1e9);
  CHECK(f.arc.full());
  CHECK((f.ellipse.centre_px - truth.centre_px).norm() < 0.5);
}

TEST_CASE("an arc under 180 degrees is flagged weak and its observation is down-weighted", "[ellipse_tracker]") {
  EllipseTracker tracker;
  WindowImage image;
  const Ellipse truth = make(170, 120, 80, 55, 0.0);
  const EllipseFeature* f = nullptr;
  for (int k = 0; k < 5; ++k) {
    REQUIRE(image.assign(frame(truth, k == 0 ? 1e9 : 170 - 15, 200 + k)));  // left ~40% of the contour free
    tracker.track_one(image, 0, truth, WindowPlacement::Previous);
    f = &tracker.features().at(0);
  }
  REQUIRE(f->found);
  CHECK_FALSE(f->arc.full());
  CHECK(f->arc.span_rad < std::numbers::pi);
  CHECK(f->weak);
  EllipseObservation obs;
  REQUIRE(tracker.observation(*f, ModelCircle{}, obs));
  CHECK(obs.sigma_px == Approx(tracker.options().sigma_px * tracker.options().weak_sigma_factor));
  CHECK(static_cast<int>(obs.points_px.size()) == f->inlier_count());
  for (const auto& p : obs.points_px) CHECK(truth.distance(p) < 2.0);
  // The weak arc keeps the shape it was placed on and fits its shift: the ellipse stays put.
  CHECK((f->ellipse.centre_px - truth.centre_px).norm() < 1.5);
  CHECK(f->ellipse.semi_major_px == Approx(80).margin(1.0));
  CHECK(f->ellipse.semi_minor_px == Approx(55).margin(1.0));
}

TEST_CASE("the ellipse tracker survives garbage projections and an ellipse outside the image", "[ellipse_tracker]") {
  EllipseTracker tracker;
  WindowImage image;
  REQUIRE(image.assign(frame(make(150, 120, 60, 40, 0), 1e9, 1)));
  tracker.track_one(image, 2, make(NAN, 0, 10, 5, 0), WindowPlacement::Previous);
  CHECK_FALSE(tracker.features().at(2).visible);
  tracker.track_one(image, 2, make(150, 120, 5, 50, 0), WindowPlacement::Previous);  // b > a: invalid
  CHECK_FALSE(tracker.features().at(2).visible);
  tracker.track_one(image, 2, make(5000, -3000, 60, 40, 0), WindowPlacement::Previous);
  CHECK_FALSE(tracker.features().at(2).found);
  tracker.track_one(image, 2, make(150, 120, 1e7, 1e6, 0), WindowPlacement::Previous);
  CHECK_FALSE(tracker.features().at(2).found);
  // And it still tracks afterwards.
  tracker.reset();
  tracker.track_one(image, 2, make(151, 121, 60, 40, 0), WindowPlacement::Previous);
  CHECK(tracker.features().at(2).found);
}

TEST_CASE("a rim the tracker does not find says why: no candidate, another contour's shape", "[ellipse_tracker]") {
  WindowImage image, blank;
  REQUIRE(image.assign(frame(make(160, 120, 70, 45, 0.2), 1e9, 3)));
  REQUIRE(blank.assign(cv::Mat(240, 320, CV_8UC3, cv::Scalar(128, 128, 128))));  // no edges at all
  EllipseTracker tracker;
  const auto track = [&](const WindowImage& on, const Ellipse& placed) -> const EllipseFeature& {
    tracker.reset();
    tracker.track_one(on, 0, placed, WindowPlacement::Projection);
    const EllipseFeature& f = tracker.features().at(0);
    REQUIRE(f.visible);
    return f;
  };
  // Placed 1.5 px off: found, nothing refused.
  const EllipseFeature& f = track(image, make(161.5, 120, 70, 45, 0.2));
  CHECK(f.found);
  CHECK(f.refused == EllipseRefusal::None);
  // Placed a quarter smaller (the prediction a quarter too far): the lines find the disc's
  // contour, whose size the prediction rules out.
  CHECK(track(image, make(160, 120, 52.5, 33.75, 0.2)).refused == EllipseRefusal::OtherShape);
  CHECK_FALSE(f.found);
  CHECK(std::string(to_string(f.refused)) == "other_shape");
  // Nothing to fit.
  CHECK(track(blank, make(160, 120, 70, 45, 0.2)).refused == EllipseRefusal::NoCandidate);
  CHECK_FALSE(f.found);
  // Found again in the next frame, the disc's (no reset between): the reason does not stay.
  tracker.track_one(image, 0, make(161.5, 120, 70, 45, 0.2), WindowPlacement::Projection);
  CHECK(f.found);
  CHECK(f.refused == EllipseRefusal::None);
}
