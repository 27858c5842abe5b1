#include "edge_support.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace epichead::vision::detail {

void EdgeGradients::compute(const cv::Mat& grey) {
  cv::Sobel(grey, gx, CV_16S, 1, 0, 3);
  cv::Sobel(grey, gy, CV_16S, 0, 1, 3);
}

namespace {

struct Counter {
  const EdgeGradients& g;
  const EdgeSupportOptions& o;
  double min_sq, min_cos;
  long samples = 0, supported = 0;
  long judged = 0, unsupported = 0;  // samples on edges judged alone, and on weak ones
  double weakest = 1;
  long edge_samples0 = 0, edge_supported0 = 0;

  void begin_edge() {
    edge_samples0 = samples;
    edge_supported0 = supported;
  }
  void end_edge() {
    const long n = samples - edge_samples0;
    if (n < o.min_edge_samples) return;
    const double share = static_cast<double>(supported - edge_supported0) / static_cast<double>(n);
    judged += n;
    if (share < o.weak_edge_share) unsupported += n;
    weakest = std::min(weakest, share);
  }

  // One sample at p with unit normal n.
  void sample(double px, double py, double nx, double ny) {
    const int w = g.gx.cols, h = g.gx.rows;
    if (!(px >= 1 && py >= 1 && px < w - 1 && py < h - 1)) return;
    ++samples;
    const int steps = static_cast<int>(std::ceil(o.radius_px));
    for (int k = -steps; k <= steps; ++k) {
      const int x = static_cast<int>(std::lround(px + k * nx)), y = static_cast<int>(std::lround(py + k * ny));
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      const double gx = g.gx.at<short>(y, x), gy = g.gy.at<short>(y, x);
      const double sq = gx * gx + gy * gy;
      if (sq < min_sq) continue;
      const double c = std::abs(gx * nx + gy * ny) / std::sqrt(sq);
      if (c >= min_cos) {
        ++supported;
        return;
      }
    }
  }
};

}  // namespace

EdgeSupport edge_support(const EdgeGradients& gradients, const VisibleModel& visible, const EdgeSupportOptions& options) {
  Counter c{gradients, options, options.min_gradient * options.min_gradient, std::cos(options.max_angle_deg * M_PI / 180.0)};
  for (const auto& e : visible.edges) {
    const Eigen::Vector2d d = e.b_px - e.a_px;
    const double len = d.norm();
    if (!(len > 2 * options.step_px)) continue;
    const Eigen::Vector2d n(-d.y() / len, d.x() / len);
    // Ends left out: corners mix two edges' gradients.
    c.begin_edge();
    for (double s = options.step_px; s < len - options.step_px + 1e-9; s += options.step_px) {
      const Eigen::Vector2d p = e.a_px + d * (s / len);
      c.sample(p.x(), p.y(), n.x(), n.y());
    }
    c.end_edge();
  }
  for (const auto& el : visible.ellipses) {
    const double perimeter = 2 * M_PI * std::sqrt(0.5 * (el.semi_major_px * el.semi_major_px + el.semi_minor_px * el.semi_minor_px));
    if (!(perimeter > 4 * options.step_px) || !std::isfinite(perimeter)) continue;
    const int n = static_cast<int>(perimeter / options.step_px);
    const double ca = std::cos(el.angle_rad), sa = std::sin(el.angle_rad);
    c.begin_edge();
    for (int i = 0; i < n; ++i) {
      const double t = 2 * M_PI * i / n;
      const double ex = el.semi_major_px * std::cos(t), ey = el.semi_minor_px * std::sin(t);
      // Normal of the ellipse in its own axes: (x/a^2, y/b^2).
      double nx = std::cos(t) / el.semi_major_px, ny = std::sin(t) / el.semi_minor_px;
      const double nn = std::hypot(nx, ny);
      nx /= nn;
      ny /= nn;
      c.sample(el.centre_px.x() + ca * ex - sa * ey, el.centre_px.y() + sa * ex + ca * ey, ca * nx - sa * ny, sa * nx + ca * ny);
    }
    c.end_edge();
  }
  EdgeSupport out{c.samples, c.supported, 0.0};
  if (c.samples >= options.min_samples) out.share = static_cast<double>(c.supported) / static_cast<double>(c.samples);
  if (c.judged > 0) out.unsupported_edge_share = static_cast<double>(c.unsupported) / static_cast<double>(c.judged);
  out.weakest_edge_support = c.weakest;
  return out;
}

namespace {

// The convex hull of what is drawn: every visible edge's ends and points around every ellipse.
void drawn_hull(const VisibleModel& visible, std::vector<cv::Point2f>& hull) {
  std::vector<cv::Point2f> drawn;
  for (const auto& e : visible.edges) {
    drawn.emplace_back(static_cast<float>(e.a_px.x()), static_cast<float>(e.a_px.y()));
    drawn.emplace_back(static_cast<float>(e.b_px.x()), static_cast<float>(e.b_px.y()));
  }
  for (const auto& el : visible.ellipses) {
    const double ca = std::cos(el.angle_rad), sa = std::sin(el.angle_rad);
    for (int i = 0; i < 32; ++i) {
      const double t = 2 * M_PI * i / 32, ex = el.semi_major_px * std::cos(t), ey = el.semi_minor_px * std::sin(t);
      drawn.emplace_back(static_cast<float>(el.centre_px.x() + ca * ex - sa * ey), static_cast<float>(el.centre_px.y() + sa * ex + ca * ey));
    }
  }
  hull.clear();
  if (drawn.size() >= 3) cv::convexHull(drawn, hull);
}

bool outside(const std::vector<cv::Point2f>& hull, const Eigen::Vector2d& p, double by_px) {
  return cv::pointPolygonTest(hull, cv::Point2f(static_cast<float>(p.x()), static_cast<float>(p.y())), true) < -by_px;
}

// Mean colours of the two strips beside a stretch of a line, 2-5 px off it.
struct Sides {
  cv::Vec3d left = 0, right = 0;
  int n = 0;
  double contrast() const { return n ? cv::norm((left - right) / n) : 0.0; }
};

}  // namespace

ColourContinuation colour_continuation(const cv::Mat& bgr, const VisibleModel& visible, const ContinuationOptions& options) {
  ColourContinuation out;
  if (bgr.empty() || bgr.type() != CV_8UC3) return out;
  std::vector<cv::Point2f> hull;
  drawn_hull(visible, hull);
  if (hull.size() < 3) return out;
  constexpr double kStep = 2.0, kNearSide = 2.0, kFarSide = 5.0, kMinEdgeContrast = 10.0, kMaxRatio = 2.0;
  constexpr int kMinPairs = 4;
  // Adds the strips beside p (line normal n); outside_only: both sides must lie outside the hull.
  const auto add = [&](Sides& sides, const Eigen::Vector2d& p, const Eigen::Vector2d& n, bool outside_only) {
    cv::Vec3d l = 0, r = 0;
    for (double k = kNearSide; k <= kFarSide; k += 1.0) {
      const Eigen::Vector2d a = p + k * n, b = p - k * n;
      const int ax = static_cast<int>(std::lround(a.x())), ay = static_cast<int>(std::lround(a.y()));
      const int bx = static_cast<int>(std::lround(b.x())), by = static_cast<int>(std::lround(b.y()));
      if (ax < 0 || ay < 0 || bx < 0 || by < 0 || ax >= bgr.cols || bx >= bgr.cols || ay >= bgr.rows || by >= bgr.rows) return;
      if (outside_only && (!outside(hull, a, 1.0) || !outside(hull, b, 1.0))) return;
      l += cv::Vec3d(bgr.at<cv::Vec3b>(ay, ax));
      r += cv::Vec3d(bgr.at<cv::Vec3b>(by, bx));
    }
    sides.left += l;
    sides.right += r;
    ++sides.n;
  };
  double sum = 0;
  for (const auto& e : visible.edges) {
    // The silhouette alone: a crease has the object on both sides, its colours may not differ.
    if (e.kind == EdgeKind::Crease || e.kind == EdgeKind::Wire) continue;
    const Eigen::Vector2d d = e.b_px - e.a_px;
    const double len = d.norm();
    if (!(len > 2 * options.gap_px + 2 * kStep)) continue;
    const Eigen::Vector2d u = d / len, n(-u.y(), u.x());
    Sides along;
    for (double s = options.gap_px; s <= len - options.gap_px; s += kStep) add(along, e.a_px + s * u, n, false);
    if (along.n < kMinPairs) continue;
    const double edge_contrast = std::max(kMinEdgeContrast, along.contrast());
    const double reach = std::min(options.max_reach_px, options.reach_share * len);
    for (const auto& [end, dir] : {std::pair{e.b_px, u}, std::pair{e.a_px, Eigen::Vector2d(-u)}}) {
      Sides past;
      for (double s = options.gap_px; s <= reach + 1e-9; s += kStep) add(past, end + s * dir, n, true);
      if (past.n < kMinPairs) continue;
      sum += std::min(kMaxRatio, past.contrast() / edge_contrast);
      ++out.ends;
    }
  }
  if (out.ends) out.ratio = sum / out.ends;
  return out;
}

}  // namespace epichead::vision::detail
