#include "epichead/vision/object_region.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace epichead::vision {

namespace {

constexpr double kNearM = 0.01;  // points nearer than this (or behind) are not drawn
constexpr int kCircleSamples = 32;

}  // namespace

ObjectRegion::ObjectRegion(const ObjectRegionOptions& options) : options_(options) {}

bool ObjectRegion::learn(const WindowImage& image, const CadModel& model, const Camera& camera,
                         const Eigen::Isometry3d& cam_T_obj) {
  ready_ = false;
  const int w = image.width_px(), h = image.height_px();
  if (w <= 0 || h <= 0) return false;
  mask_.create(h, w, CV_8U);
  mask_.setTo(0);
  // Draws the convex hull of object points (nothing when one is not in front of the camera), and
  // grows the box of what was drawn.
  int x0 = w, y0 = h, x1 = -1, y1 = -1;
  const auto fill = [&](auto&& points_obj, int n) {
    polygon_.clear();
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = cam_T_obj * points_obj(i);
      if (!(p.z() > kNearM)) return;
      const Eigen::Vector2d px = camera.project(p);
      if (!px.allFinite() || px.cwiseAbs().maxCoeff() > 1e6) return;
      polygon_.emplace_back(static_cast<int>(std::lround(px.x())), static_cast<int>(std::lround(px.y())));
    }
    if (polygon_.size() < 3) return;
    cv::convexHull(polygon_, hull_);
    cv::fillConvexPoly(mask_, hull_, cv::Scalar(255));
    for (const cv::Point& q : hull_) {
      x0 = std::min(x0, q.x);
      y0 = std::min(y0, q.y);
      x1 = std::max(x1, q.x);
      y1 = std::max(y1, q.y);
    }
  };
  // A closed model's triangles cover its silhouette, front faces and back faces alike.
  for (const ModelFace& face : model.faces)
    for (const auto& t : face.triangles) fill([&](int i) { return model.vertices[static_cast<std::size_t>(t[static_cast<std::size_t>(i)])]; }, 3);
  const auto on_circle_point = [](const Eigen::Vector3d& centre, const Eigen::Vector3d& normal, double radius, int i, int n) {
    const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.normalized().cross(u);
    const double a = 2 * M_PI * i / n;
    return Eigen::Vector3d(centre + radius * (std::cos(a) * u + std::sin(a) * v));
  };
  for (const ModelCircle& c : model.circles)
    fill([&](int i) { return on_circle_point(c.centre_obj, c.normal_obj, c.radius_m, i, kCircleSamples); }, kCircleSamples);
  for (const ModelCylinder& c : model.cylinders) {
    const Eigen::Vector3d axis = c.axis_b_obj - c.axis_a_obj;
    if (!(axis.norm() > 0)) continue;
    fill([&](int i) {
      return on_circle_point(i < kCircleSamples ? c.axis_a_obj : c.axis_b_obj, axis, c.radius_m, i % kCircleSamples, kCircleSamples);
    }, 2 * kCircleSamples);
  }

  // Distances to the outline from inside and from outside, within the box of what was drawn
  // grown by the background ring (the rest of the frame is in neither histogram).
  const int pad = static_cast<int>(std::ceil(options_.outer_margin_px + options_.ring_px)) + 2;
  x0 = std::max(x0 - pad, 0);
  y0 = std::max(y0 - pad, 0);
  x1 = std::min(x1 + pad, w - 1);
  y1 = std::min(y1 + pad, h - 1);
  if (x1 < x0 || y1 < y0) return false;  // nothing drawn inside the frame
  const cv::Rect box(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  cv::distanceTransform(mask_(box), inside_px_, cv::DIST_L2, cv::DIST_MASK_3);
  cv::bitwise_not(mask_(box), not_mask_);
  cv::distanceTransform(not_mask_, outside_px_, cv::DIST_L2, cv::DIST_MASK_3);
  std::array<float, kBins * kBins * kBins> object{}, background{};
  float n_object = 0, n_background = 0;
  const float* px = image.pixels();
  const float inner = static_cast<float>(options_.inner_margin_px), outer = static_cast<float>(options_.outer_margin_px);
  const float far = static_cast<float>(options_.outer_margin_px + options_.ring_px);
  for (int y = 0; y < box.height; y += 2) {
    const float* din = inside_px_.ptr<float>(y);
    const float* dout = outside_px_.ptr<float>(y);
    for (int x = 0; x < box.width; x += 2) {
      const float* p = px + (static_cast<std::size_t>(y + y0) * w + (x + x0)) * kCueChannels;
      const int b = (bin(p[0]) * kBins + bin(p[1])) * kBins + bin(p[2]);
      if (din[x] > inner) { object[b] += 1; n_object += 1; }
      else if (dout[x] > outer && dout[x] <= far) { background[b] += 1; n_background += 1; }
    }
  }
  if (n_object < options_.min_samples || n_background < options_.min_samples) return false;
  // Densities with one count spread over all bins (an unseen colour says little either way).
  const float spread = 1.0f / static_cast<float>(object.size());
  for (std::size_t b = 0; b < object.size(); ++b) {
    const float po = (object[b] + spread) / (n_object + 1), pb = (background[b] + spread) / (n_background + 1);
    p_object_[b] = po / (po + pb);
  }
  ready_ = true;
  return true;
}

std::int8_t ObjectRegion::outer_side(const Eigen::Vector2d& point_px, const Eigen::Vector2d& dir) const {
  if (!ready_) return 0;
  const auto inside = [&](const Eigen::Vector2d& p) {
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    return x >= 0 && y >= 0 && x < mask_.cols && y < mask_.rows && mask_.at<std::uint8_t>(y, x) != 0;
  };
  const bool plus = inside(point_px + options_.probe_px * dir), minus = inside(point_px - options_.probe_px * dir);
  if (plus == minus) return 0;
  return plus ? std::int8_t{-1} : std::int8_t{1};
}

float ObjectRegion::object_probability(const IntervalCues& cues) const {
  if (!ready_ || !cues.valid) return 0.5f;
  const int b = (bin(cues.value[0]) * kBins + bin(cues.value[1])) * kBins + bin(cues.value[2]);
  return p_object_[static_cast<std::size_t>(b)];
}

}  // namespace epichead::vision
