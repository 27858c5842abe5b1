#include "epichead/vision/object_region.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace epichead::vision {

namespace {

constexpr double kNearM = 0.01;  // points nearer than this (or behind) are not drawn
constexpr int kCircleSamples = 32;

// The distance to the outline is OpenCV's distanceTransform(DIST_L2, DIST_MASK_3), the
// histograms were first made with it: a chamfer distance with steps of 0.955 px (straight) and
// 1.3693 px (diagonal) in 16.16 fixed point. It is computed here, with the same integers, in a
// buffer kept between starts, over only the part of the frame that needs it: OpenCV allocates
// a frame-sized scratch image per call, whose page faults made most of a start's cost.
constexpr int kFixedShift = 16;
const int kStraight = cvRound(0.955f * (1 << kFixedShift));
const int kDiagonal = cvRound(1.3693f * (1 << kFixedShift));
constexpr std::int32_t kFar = std::numeric_limits<std::int32_t>::max() >> 2;  // no source
constexpr float kFixedToPx = 1.f / (1 << kFixedShift);

// The chamfer distance of each pixel of region to the nearest source pixel in it (inside: the
// pixels mask leaves 0; outside: the ones it sets), into dist: region.height + 2 rows of
// region.width + 2, whose border stays kFar. The two raster passes of the chamfer transform,
// each split into a part across rows (vectorised) and the running minimum along the row.
void chamfer_distance(const cv::Mat& mask, const cv::Rect& region, bool inside, std::int32_t* dist) {
  const int w = region.width, h = region.height, stride = w + 2;
  std::fill(dist, dist + stride, kFar);
  std::fill(dist + static_cast<std::ptrdiff_t>(h + 1) * stride, dist + static_cast<std::ptrdiff_t>(h + 2) * stride, kFar);
  const std::int32_t straight = kStraight, diagonal = kDiagonal;
  for (int y = 0; y < h; ++y) {
    std::int32_t* __restrict row = dist + static_cast<std::ptrdiff_t>(y + 1) * stride + 1;
    const std::int32_t* __restrict up = row - stride;
    const std::uint8_t* __restrict m = mask.ptr<std::uint8_t>(region.y + y) + region.x;
    row[-1] = row[w] = kFar;
    for (int x = 0; x < w; ++x) {
      const std::int32_t v = std::min({up[x - 1] + diagonal, up[x] + straight, up[x + 1] + diagonal});
      row[x] = ((m[x] == 0) == inside) ? 0 : v;
    }
    std::int32_t left = kFar;
    for (int x = 0; x < w; ++x) row[x] = left = std::min(row[x], left + straight);
  }
  for (int y = h - 1; y >= 0; --y) {
    std::int32_t* __restrict row = dist + static_cast<std::ptrdiff_t>(y + 1) * stride + 1;
    const std::int32_t* __restrict down = row + stride;
    for (int x = 0; x < w; ++x) row[x] = std::min({row[x], down[x - 1] + diagonal, down[x] + straight, down[x + 1] + diagonal});
    std::int32_t right = kFar;
    for (int x = w - 1; x >= 0; --x) row[x] = right = std::min(row[x], right + straight);
  }
}

}  // namespace

ObjectRegion::ObjectRegion(const ObjectRegionOptions& options) : options_(options) {}

void ObjectRegion::reserve(int width_px, int height_px) {
  if (width_px <= 0 || height_px <= 0) return;
  if (mask_.cols != width_px || mask_.rows != height_px) {
    mask_.create(height_px, width_px, CV_8U);
    mask_.setTo(0);
    dirty_ = {};
  }
  const std::size_t cells = static_cast<std::size_t>(width_px + 2) * static_cast<std::size_t>(height_px + 2);
  if (distance_.size() < cells) distance_.assign(cells, kFar);
}

cv::Rect ObjectRegion::draw(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj) {
  if (!dirty_.empty()) mask_(dirty_).setTo(0);
  // Draws the convex hull of object points (nothing when one is not in front of the camera), and
  // grows the box of what was drawn.
  int x0 = mask_.cols, y0 = mask_.rows, x1 = -1, y1 = -1;
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
  const cv::Rect drawn(x0, y0, x1 - x0 + 1, y1 - y0 + 1);  // negative sizes when nothing was drawn
  dirty_ = x1 < x0 || y1 < y0 ? cv::Rect() : drawn & cv::Rect(0, 0, mask_.cols, mask_.rows);
  return drawn;
}

int ObjectRegion::count(const WindowImage& image, const cv::Rect& box, const cv::Rect& region, bool inside, float min_px,
                        float max_px, Histogram& histogram) {
  if (region.empty()) return 0;
  chamfer_distance(mask_, region, inside, distance_.data());
  const int stride = region.width + 2, w = image.width_px();
  image.prepare(region);
  const float* px = image.pixels();
  int n = 0;
  // The grid's first row and column in region (every second pixel of box from its corner).
  const int gy = (region.y - box.y) & 1, gx = (region.x - box.x) & 1;
  for (int y = gy; y < region.height; y += 2) {
    const std::int32_t* d = distance_.data() + static_cast<std::ptrdiff_t>(y + 1) * stride + 1;
    const float* row = px + static_cast<std::size_t>(y + region.y) * w * kCueChannels;
    for (int x = gx; x < region.width; x += 2) {
      const float d_px = static_cast<float>(d[x] * kFixedToPx);  // as OpenCV converts it
      if (!(d_px > min_px && d_px <= max_px)) continue;
      const float* p = row + static_cast<std::size_t>(x + region.x) * kCueChannels;
      ++histogram[static_cast<std::size_t>((bin(p[0]) * kBins + bin(p[1])) * kBins + bin(p[2]))];
      ++n;
    }
  }
  return n;
}

bool ObjectRegion::learn(const WindowImage& image, const CadModel& model, const Camera& camera,
                         const Eigen::Isometry3d& cam_T_obj) {
  ready_ = false;
  const int w = image.width_px(), h = image.height_px();
  if (w <= 0 || h <= 0) return false;
  reserve(w, h);
  const cv::Rect drawn = draw(model, camera, cam_T_obj);
  // The histograms' box: what was drawn grown by the background ring (the rest of the frame is
  // in neither histogram).
  const int pad = static_cast<int>(std::ceil(options_.outer_margin_px + options_.ring_px)) + 2;
  const int x0 = std::max(drawn.x - pad, 0), y0 = std::max(drawn.y - pad, 0);
  const int x1 = std::min(drawn.x + drawn.width - 1 + pad, w - 1), y1 = std::min(drawn.y + drawn.height - 1 + pad, h - 1);
  if (x1 < x0 || y1 < y0) return false;  // nothing drawn inside the frame
  const cv::Rect box(x0, y0, x1 - x0 + 1, y1 - y0 + 1);
  // The object's pixels all lie in what was drawn, and the ring of pixels just beyond it (not
  // drawn) is nearer to each of them than anything further out: their distances need only
  // that much of the box.
  const cv::Rect inner_region = dirty_.empty() ? cv::Rect() : cv::Rect(dirty_.x - 1, dirty_.y - 1, dirty_.width + 2, dirty_.height + 2) & box;
  object_.fill(0);
  background_.fill(0);
  const float inner = static_cast<float>(options_.inner_margin_px), outer = static_cast<float>(options_.outer_margin_px);
  const float far = static_cast<float>(options_.outer_margin_px + options_.ring_px);
  const int n_object = count(image, box, inner_region, true, inner, std::numeric_limits<float>::infinity(), object_);
  const int n_background = count(image, box, box, false, outer, far, background_);
  if (n_object < options_.min_samples || n_background < options_.min_samples) return false;
  // Densities with one count spread over all bins (an unseen colour says little either way).
  const float spread = 1.0f / static_cast<float>(object_.size());
  const float n_o = static_cast<float>(n_object), n_b = static_cast<float>(n_background);
  for (std::size_t b = 0; b < object_.size(); ++b) {
    const float po = (static_cast<float>(object_[b]) + spread) / (n_o + 1);
    const float pb = (static_cast<float>(background_[b]) + spread) / (n_b + 1);
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
