// ObjectRegion: the model drawn at a pose, the object's and the background's colours, which
// side of an edge leaves the object; and with it, a rim told from a printed border just inside
// it (issue 19: a can's bottom rim and the lower border of its label).
#include <catch2/catch.hpp>

#include <cmath>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/object_region.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

constexpr double kFocalPx = 300, kRadiusM = 0.05;
const Camera kCamera(320, 240, Intrinsics{kFocalPx, kFocalPx, 160, 120});

// A disc facing the camera: radius_px in the image at distance f r / radius_px.
Eigen::Isometry3d disc_at(double radius_px) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0, 0, kFocalPx * kRadiusM / radius_px);
  return T;
}

CadModel disc_model() {
  CadModel m;
  ModelCircle c;
  c.radius_m = kRadiusM;
  m.circles.push_back(c);
  return m;
}

// A dark red disc with a light band along its rim (printed: a label ending 8 px inside the
// rim, a white foot beyond it), on a background of green and brown blocks.
cv::Mat frame(double rim_px, double label_px) {
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG blocks(5);
  for (int y = 0; y < img.rows; y += 10)
    for (int x = 0; x < img.cols; x += 10) {
      const bool green = blocks.uniform(0, 2) == 0;
      const cv::Scalar c = green ? cv::Scalar(50, 140 + blocks.uniform(0, 30), 50) : cv::Scalar(40, 70, 110 + blocks.uniform(0, 30));
      cv::rectangle(img, {x, y}, {x + 9, y + 9}, c, cv::FILLED);
    }
  cv::circle(img, {160, 120}, static_cast<int>(rim_px), cv::Scalar(225, 230, 235), cv::FILLED, cv::LINE_AA);
  cv::circle(img, {160, 120}, static_cast<int>(label_px), cv::Scalar(30, 30, 170), cv::FILLED, cv::LINE_AA);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  return img;
}

Ellipse circle_px(double r) {
  Ellipse e;
  e.centre_px = {160, 120};
  e.semi_major_px = e.semi_minor_px = r;
  return e;
}

}  // namespace

TEST_CASE("the object region learns the object's and the background's colours from the model drawn at a pose", "[object_region]") {
  WindowImage image;
  REQUIRE(image.assign(frame(50, 42)));
  ObjectRegion region;
  REQUIRE(region.learn(image, disc_model(), kCamera, disc_at(47)));  // the start: 3 px small
  IntervalCues red, white, green;
  red.valid = white.valid = green.valid = true;
  const auto cues_of = [](double b, double g, double r) {
    IntervalCues c;
    c.valid = true;
    const double sum = b + g + r + 24;
    c.value = {static_cast<float>((b + g + r) / 3), static_cast<float>(255 * (r + 8) / sum), static_cast<float>(255 * (g + 8) / sum), 0};
    return c;
  };
  CHECK(region.object_probability(cues_of(30, 30, 170)) > 0.9f);
  CHECK(region.object_probability(cues_of(225, 230, 235)) > 0.9f);  // the band along the outline counts as object
  CHECK(region.object_probability(cues_of(50, 150, 50)) < 0.1f);
  CHECK(region.object_probability(IntervalCues{}) == 0.5f);  // no interval: no evidence
  // On the drawn outline (47 px right of the centre) the side of growing x leaves the object;
  // inside it, neither side does.
  CHECK(region.outer_side({207, 120}, {1, 0}) == 1);
  CHECK(region.outer_side({207, 120}, {-1, 0}) == -1);
  CHECK(region.outer_side({180, 120}, {1, 0}) == 0);
  CHECK(region.outer_side({300, 120}, {1, 0}) == 0);
  region.clear();
  CHECK(region.outer_side({207, 120}, {1, 0}) == 0);
  CHECK(region.object_probability(cues_of(30, 30, 170)) == 0.5f);
}

TEST_CASE("a model that does not fill enough of the frame, or lies behind the camera, learns nothing", "[object_region]") {
  WindowImage image;
  REQUIRE(image.assign(frame(50, 42)));
  ObjectRegion region;
  CHECK_FALSE(region.learn(image, disc_model(), kCamera, disc_at(3)));
  Eigen::Isometry3d behind = disc_at(47);
  behind.translation().z() = -behind.translation().z();
  CHECK_FALSE(region.learn(image, disc_model(), kCamera, behind));
  CHECK_FALSE(region.ready());
}

TEST_CASE("from a start between a printed border and the rim, outline colours put the rim on the rim", "[object_region]") {
  // The label's border is 8 px inside the rim; the start is 4 px small, half-way between them.
  // The references, from beside the start's projection, are the label's red inside and the
  // background outside: each edge agrees with one of them, and EPIC takes the border. The
  // colours beyond it (the white foot, the object's) say it is not the outline.
  const double rim = 50, label = 42, start = 46;
  WindowImage image;
  REQUIRE(image.assign(frame(rim, label)));
  ObjectRegion region;
  REQUIRE(region.learn(image, disc_model(), kCamera, disc_at(start)));
  for (const bool weigh : {false, true}) {
    EllipseTrackerOptions options;
    options.mode = EpicMode::Epic;
    options.side = RimSide::Both;
    EllipseTracker tracker(options);
    tracker.set_outline(weigh ? &region : nullptr);
    tracker.track_one(image, 0, circle_px(start), WindowPlacement::Projection);
    const EllipseFeature& f = tracker.features().at(0);
    INFO((weigh ? "with" : "without") << " outline colours: semi-axes " << f.ellipse.semi_major_px << ", " << f.ellipse.semi_minor_px);
    REQUIRE(f.found);
    const double found = 0.5 * (f.ellipse.semi_major_px + f.ellipse.semi_minor_px);
    if (weigh) CHECK(found == Approx(rim).margin(1.5));
    else CHECK(found == Approx(label).margin(1.5));  // the case the colours are for
  }
}
