#include "edge_support.h"

#include <cmath>

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
    for (double s = options.step_px; s < len - options.step_px + 1e-9; s += options.step_px) {
      const Eigen::Vector2d p = e.a_px + d * (s / len);
      c.sample(p.x(), p.y(), n.x(), n.y());
    }
  }
  for (const auto& el : visible.ellipses) {
    const double perimeter = 2 * M_PI * std::sqrt(0.5 * (el.semi_major_px * el.semi_major_px + el.semi_minor_px * el.semi_minor_px));
    if (!(perimeter > 4 * options.step_px) || !std::isfinite(perimeter)) continue;
    const int n = static_cast<int>(perimeter / options.step_px);
    const double ca = std::cos(el.angle_rad), sa = std::sin(el.angle_rad);
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
  }
  EdgeSupport out{c.samples, c.supported, 0.0};
  if (c.samples >= options.min_samples) out.share = static_cast<double>(c.supported) / static_cast<double>(c.samples);
  return out;
}

}  // namespace epichead::vision::detail
