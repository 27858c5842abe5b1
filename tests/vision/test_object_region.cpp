// ObjectRegion: the model drawn at a pose, the object's and the background's colours, which
// side of an edge leaves the object; and with it, a rim told from a printed border just inside
// it (issue 19: a can's bottom rim and the lower border of its label).
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

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

namespace {

// The object region as first written, with OpenCV's distance transforms over the whole box and a
// frame-sized mask drawn afresh: what ObjectRegion must reproduce exactly, with less work.
struct ReferenceRegion {
  cv::Mat mask;
  std::array<float, 512> p_object{};
  bool ready = false;
};

ReferenceRegion reference_region(const WindowImage& frame_image, const CadModel& model, const Camera& camera,
                                 const Eigen::Isometry3d& cam_T_obj, const ObjectRegionOptions& o = {}) {
  // A copy with every pixel converted: the region under test prepares its own pixels.
  WindowImage image = frame_image;
  image.prepare_all();
  ReferenceRegion r;
  const int w = image.width_px(), h = image.height_px();
  r.mask = cv::Mat::zeros(h, w, CV_8U);
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  const auto fill = [&](const std::vector<Eigen::Vector3d>& points_obj) {
    std::vector<cv::Point> polygon, hull;
    for (const Eigen::Vector3d& p_obj : points_obj) {
      const Eigen::Vector3d p = cam_T_obj * p_obj;
      if (!(p.z() > 0.01)) return;
      const Eigen::Vector2d px = camera.project(p);
      polygon.emplace_back(static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y())));
    }
    cv::convexHull(polygon, hull);
    cv::fillConvexPoly(r.mask, hull, cv::Scalar(255));
    for (const cv::Point& q : hull) {
      x0 = std::min(x0, q.x);
      y0 = std::min(y0, q.y);
      x1 = std::max(x1, q.x);
      y1 = std::max(y1, q.y);
    }
  };
  const auto circle = [](const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, int i) {
    const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.normalized().cross(u);
    const double a = 2 * M_PI * i / 32;
    return Eigen::Vector3d(centre + radius * (std::cos(a) * u + std::sin(a) * v));
  };
  for (const ModelFace& face : model.faces)
    for (const auto& t : face.triangles)
      fill({model.vertices[static_cast<std::size_t>(t[0])], model.vertices[static_cast<std::size_t>(t[1])], model.vertices[static_cast<std::size_t>(t[2])]});
  for (const ModelCircle& c : model.circles) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 32; ++i) points.push_back(circle(c.centre_obj, c.normal_obj, c.radius_m, i));
    fill(points);
  }
  for (const ModelCylinder& c : model.cylinders) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < 64; ++i) points.push_back(circle(i < 32 ? c.axis_a_obj : c.axis_b_obj, c.axis_b_obj - c.axis_a_obj, c.radius_m, i % 32));
    fill(points);
  }
  const int pad = static_cast<int>(std::ceil(o.outer_margin_px + o.ring_px)) + 2;
  x0 = std::max(x0 - pad, 0);
  y0 = std::max(y0 - pad, 0);
  x1 = std::min(x1 + pad, w - 1);
  y1 = std::min(y1 + pad, h - 1);
  if (x1 < x0 || y1 < y0) return r;
  const cv::Rect box(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  cv::Mat inside, outside, not_mask;
  cv::distanceTransform(r.mask(box), inside, cv::DIST_L2, cv::DIST_MASK_3);
  cv::bitwise_not(r.mask(box), not_mask);
  cv::distanceTransform(not_mask, outside, cv::DIST_L2, cv::DIST_MASK_3);
  std::array<float, 512> object{}, background{};
  float n_object = 0, n_background = 0;
  const auto bin = [](float v) { return std::clamp(static_cast<int>(v * (8 / 256.0f)), 0, 7); };
  for (int y = 0; y < box.height; y += 2)
    for (int x = 0; x < box.width; x += 2) {
      const float* p = image.pixels() + (static_cast<std::size_t>(y + y0) * w + (x + x0)) * kCueChannels;
      const int b = (bin(p[0]) * 8 + bin(p[1])) * 8 + bin(p[2]);
      const float din = inside.at<float>(y, x), dout = outside.at<float>(y, x);
      if (din > o.inner_margin_px) { object[b] += 1; n_object += 1; }
      else if (dout > o.outer_margin_px && dout <= o.outer_margin_px + o.ring_px) { background[b] += 1; n_background += 1; }
    }
  if (n_object < o.min_samples || n_background < o.min_samples) return r;
  for (std::size_t b = 0; b < 512; ++b) {
    const float po = (object[b] + 1.0f / 512) / (n_object + 1), pb = (background[b] + 1.0f / 512) / (n_background + 1);
    r.p_object[b] = po / (po + pb);
  }
  r.ready = true;
  return r;
}

// A can: its cylinder and its two rims.
CadModel can_model() {
  CadModel m;
  ModelCylinder body;
  body.axis_b_obj = {0, 0, 0.12};
  body.radius_m = 0.033;
  m.cylinders.push_back(body);
  for (const double z : {0.0, 0.12}) {
    ModelCircle rim;
    rim.centre_obj = {0, 0, z};
    rim.radius_m = 0.033;
    m.circles.push_back(rim);
  }
  return m;
}

// A box of triangles, 16 x 7 x 8 cm (the tea box's size).
CadModel box_model() {
  CadModel m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1 ? 0.165 : 0.0, i & 2 ? 0.068 : 0.0, i & 4 ? -0.08 : 0.0);
  for (const auto& q : std::vector<std::array<int, 4>>{{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}}) {
    ModelFace f;
    f.vertices = {q[0], q[1], q[2], q[3]};
    f.triangles = {{q[0], q[1], q[2]}, {q[0], q[2], q[3]}};
    m.faces.push_back(f);
  }
  return m;
}

}  // namespace

TEST_CASE("the object region learns exactly what OpenCV's distance transforms over the whole box give", "[object_region]") {
  // Random colours in small blocks, so that a single pixel classified differently changes a
  // histogram; poses near, far, and across every border of the frame, one region reused for
  // all of them (what the last start drew must not remain).
  cv::Mat img(240, 320, CV_8UC3);
  cv::randu(img, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::resize(img(cv::Rect(0, 0, 80, 60)), img, img.size(), 0, 0, cv::INTER_NEAREST);
  WindowImage image;
  REQUIRE(image.assign(img));
  ObjectRegion region;
  cv::RNG rng(24);
  int learnt = 0, compared = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const CadModel model = trial % 2 ? box_model() : can_model();
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(rng.uniform(0.0, 2 * M_PI), Eigen::Vector3d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)).normalized()).toRotationMatrix();
    const double z = rng.uniform(0.25, 0.9);
    pose.translation() = Eigen::Vector3d(rng.uniform(-0.6, 0.6) * z, rng.uniform(-0.45, 0.45) * z, z);
    REQUIRE(image.assign(img));  // no pixel converted: learn() must ask for those it reads
    const ReferenceRegion expected = reference_region(image, model, kCamera, pose);
    INFO("trial " << trial);
    REQUIRE(region.learn(image, model, kCamera, pose) == expected.ready);
    learnt += expected.ready;
    if (!expected.ready) continue;
    for (int b = 0; b < 512; ++b) {
      IntervalCues cues;
      cues.valid = true;
      cues.value = {16.0f + 32 * (b / 64), 16.0f + 32 * (b / 8 % 8), 16.0f + 32 * (b % 8), 0};
      if (region.object_probability(cues) != expected.p_object[static_cast<std::size_t>(b)]) FAIL("bin " << b);
    }
    for (int y = 0; y < 240; y += 3)
      for (int x = 0; x < 320; x += 3) {
        const Eigen::Vector2d at(x, y), dir(0.6, 0.8);
        const auto inside = [&](const Eigen::Vector2d& p) {
          const int px = static_cast<int>(std::lround(p.x())), py = static_cast<int>(std::lround(p.y()));
          return px >= 0 && py >= 0 && px < 320 && py < 240 && expected.mask.at<std::uint8_t>(py, px) != 0;
        };
        const bool p = inside(at + 3 * dir), m = inside(at - 3 * dir);
        const int side = p == m ? 0 : (p ? -1 : 1);
        if (region.outer_side(at, dir) != side) FAIL("outer side at " << x << ", " << y);
      }
    ++compared;
  }
  CHECK(learnt >= 20);  // most poses see enough of the object and of its background
  CHECK(compared == learnt);
}
