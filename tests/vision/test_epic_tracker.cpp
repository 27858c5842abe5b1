// LineTracker: windows follow each line from its previous result, references are kept per
// model edge, and the modes are selectable.
#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/line_tracker.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

// A textured brown box on a dark background with its left side at x0, 100 px wide, rows 60..160.
cv::Mat box_frame(double x0, unsigned seed) {
  cv::Mat img(220, 260, CV_8UC3, cv::Scalar(40, 40, 40));
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      // 4x horizontal supersampling for sub-pixel box position.
      double cover = 0;
      for (int i = 0; i < 4; ++i) {
        const double xs = x - 0.375 + 0.25 * i;
        cover += (xs > x0 && xs < x0 + 100 && y >= 60 && y < 160) ? 0.25 : 0.0;
      }
      const cv::Vec3d box(60, 100, 140), bg(40, 40, 40);
      const cv::Vec3d c = bg + (box - bg) * cover;
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                          cv::saturate_cast<uchar>(c[2]));
    }
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0, 1.5);
  cv::add(img, noise, img, cv::noArray(), CV_8UC3);
  return img;
}

// The box's outline at x0 as a visible model, traversed so that the object is on the Left.
VisibleModel box_model(double x0) {
  const double x1 = x0 + 100, y0 = 60, y1 = 160;
  const Eigen::Vector2d p[4] = {{x1, y0}, {x0, y0}, {x0, y1}, {x1, y1}};
  VisibleModel m;
  for (int k = 0; k < 4; ++k) {
    VisibleEdge e;
    e.edge = k;
    e.side = ObjectSide::Left;
    e.a_px = p[k];
    e.b_px = p[(k + 1) % 4];
    m.edges.push_back(e);
  }
  return m;
}

double x_error(const LineFeature& f, double x_true) {
  const LineCandidate& c = f.result.candidates[f.selected];
  return std::max(std::abs(c.a_px.x() - x_true), std::abs(c.b_px.x() - x_true));
}

}  // namespace

TEST_CASE("windows follow each line from its previous result beyond the window half-width", "[line_tracker]") {
  // The box moves 2 px per frame, 24 px in all (the window reaches 19.5 px either side), while
  // the model stays projected at frame 0's position.
  const VisibleModel model = box_model(80);
  for (EpicMode mode : {EpicMode::Epic, EpicMode::EpicSingle, EpicMode::Gradient}) {
    LineTrackerOptions options;
    options.mode = mode;
    LineTracker previous(options), projection(options);
    WindowImage image;
    double x0 = 80;
    for (int f = 0; f <= 12; ++f, x0 += 2) {
      REQUIRE(image.assign(box_frame(x0, 10 + f)).has_value());
      previous.track(image, model, WindowPlacement::Previous);
      projection.track(image, model, WindowPlacement::Projection);
    }
    x0 -= 2;
    INFO("mode " << static_cast<int>(mode));
    const auto& left = previous.features()[1];   // (x0, y0) -> (x0, y1)
    const auto& right = previous.features()[3];  // (x1, y1) -> (x1, y0)
    REQUIRE(left.found);
    REQUIRE(right.found);
    CHECK(x_error(left, x0) < 0.3);
    CHECK(x_error(right, x0 + 100) < 0.3);
    // Windows on the frame-0 projection no longer contain the vertical edges.
    const auto& stale = projection.features()[1];
    CHECK((!stale.found || x_error(stale, x0) > 3));
  }
}

TEST_CASE("references are initialised per model edge and only object-side ones are used", "[line_tracker]") {
  const VisibleModel model = box_model(80);
  LineTracker tracker;
  WindowImage image;
  REQUIRE(image.assign(box_frame(80, 1)).has_value());
  tracker.track(image, model, WindowPlacement::Previous);
  REQUIRE(tracker.features().size() == 4);
  for (const LineFeature& f : tracker.features()) {
    CHECK(f.visible);
    CHECK(f.found);
    CHECK(f.refs.initialised);
    CHECK(f.refs.side[0].mu[0] == Approx(100).margin(5));  // the box's intensity (60+100+140)/3
    CHECK(f.refs.side[1].mu[0] == 0.0f);                   // background side: never set
  }
  // An edge missing from the visible model is not processed and loses its previous result.
  VisibleModel three = model;
  three.edges.pop_back();
  tracker.track(image, three, WindowPlacement::Previous);
  CHECK_FALSE(tracker.features()[3].visible);
  CHECK_FALSE(tracker.features()[3].has_previous);
  CHECK(tracker.features()[3].refs.initialised);  // kept for when it comes back
}
