#include "epichead/vision/tracker_lines.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <opencv2/core.hpp>

#if defined(__SSE4_1__)
#include <immintrin.h>
#endif

namespace epichead::vision {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

TrackerLine line_at(const Ellipse& e, double t) {
  TrackerLine l;
  l.centre_px = e.point(t);
  l.normal = e.outward_normal(t);
  l.polar_rad = e.polar_of_param(t);
  return l;
}

// Cumulative arc length over [t0, t0 + dt] at kSteps equal parameter steps (midpoint rule):
// accurate to far below a pixel for any ellipse a tracker line can follow.
constexpr int kSteps = 96;
struct ArcTable {
  std::array<double, kSteps + 1> s{};
  double t0 = 0, dt = 0;
  ArcTable(const Ellipse& e, double t_begin, double t_span) : t0(t_begin), dt(t_span / kSteps) {
    // |dp/dt| = sqrt(a^2 sin^2 t + b^2 cos^2 t); cos and sin of the midpoints by rotation (two
    // libm calls instead of 2 kSteps; the recurrence drifts by ~1e-14 over the table).
    const double a2 = e.semi_major_px * e.semi_major_px, b2 = e.semi_minor_px * e.semi_minor_px;
    const double cd = std::cos(dt), sd = std::sin(dt);
    double c = std::cos(t0 + 0.5 * dt), sn = std::sin(t0 + 0.5 * dt);
    for (int k = 0; k < kSteps; ++k) {
      s[k + 1] = s[k] + std::sqrt(a2 * sn * sn + b2 * c * c) * std::fabs(dt);
      const double c_next = c * cd - sn * sd;
      sn = sn * cd + c * sd;
      c = c_next;
    }
  }
  double length() const { return s[kSteps]; }
  double param_at(double length_px) const {
    const auto it = std::lower_bound(s.begin() + 1, s.end(), length_px);
    const int k = std::clamp(static_cast<int>(it - s.begin()) - 1, 0, kSteps - 1);
    const double seg = s[k + 1] - s[k];
    const double f = seg > 0 ? std::clamp((length_px - s[k]) / seg, 0.0, 1.0) : 0.0;
    return t0 + (k + f) * dt;
  }
};

}  // namespace

double spread_tracker_lines(const Ellipse& e, const EllipseArc& arc, int count, TrackerLine* out) {
  if (count < 2 || !e.valid() || !std::isfinite(arc.begin_rad) || !std::isfinite(arc.span_rad)) return 0;
  const double t_begin = e.param_of_polar(arc.begin_rad);
  double t_span = kTwoPi;
  if (!arc.full()) {
    t_span = e.param_of_polar(arc.begin_rad + arc.span_rad) - t_begin;
    t_span -= kTwoPi * std::floor(t_span / kTwoPi);  // into [0, 2 pi): the map polar -> t is monotonic
    if (t_span <= 0) return 0;
  }
  const ArcTable table(e, t_begin, t_span);
  const double gaps = arc.full() ? count : count - 1;  // a closed contour has as many gaps as lines
  const double step = table.length() / gaps;
  for (int i = 0; i < count; ++i) out[i] = line_at(e, table.param_at(step * i));
  return step;
}

TrackerLine tracker_line_beyond(const Ellipse& e, double polar_rad, double step_px, int direction) {
  // Two half steps at the local speed, so the step is right also where the curvature changes.
  double t = e.param_of_polar(polar_rad);
  for (int k = 0; k < 2; ++k) {
    const double speed = std::max(e.tangent(t).norm(), 1e-9);
    t += direction * 0.5 * step_px / speed;
  }
  return line_at(e, t);
}

TrackerLineWindow::TrackerLineWindow(int max_lines, int width_px)
    : max_lines_(std::max(max_lines, 2)),
      width_px_(std::clamp(width_px, 8, kMaxWindowWidth)),
      window_(WindowOptions{width_px_, max_lines_}) {
  (void)grey_stub_.assign(cv::Mat(2, 2, CV_8UC1, cv::Scalar(0)));
  (void)colour_stub_.assign(cv::Mat(2, 2, CV_8UC3, cv::Scalar(0, 0, 0)));
  lines_.reserve(static_cast<std::size_t>(max_lines_));
}

bool TrackerLineWindow::layout(int rows, bool colour) {
  if (rows == rows_ && colour == colour_ && window_.geometry().rows == rows) return true;
  // LineWindow's geometry is only set by sample(): a vertical segment of exactly `rows` px gives
  // `rows` rows at a 1 px step and width_px columns (plan_rows with max_rows >= rows). The
  // sampled values are overwritten by sample() below; this runs only when the row count or the
  // frame kind changes (full ellipse <-> arc), never per frame in steady state.
  if (!window_.sample(colour ? colour_stub_ : grey_stub_, Eigen::Vector2d(0, 0), Eigen::Vector2d(0, rows))) return false;
  const WindowGeometry& g = window_.geometry();
  rows_ = rows;
  colour_ = colour;
  return g.rows == rows && g.cols == width_px_;
}

bool TrackerLineWindow::sample(const WindowImage& image, const TrackerLine* lines, int n) {
  lines_.clear();
  if (n < 2 || n > max_lines_ || image.width_px() < 2 || image.height_px() < 2) { rows_ = 0; return false; }
  for (int r = 0; r < n; ++r)
    if (!lines[r].centre_px.allFinite() || !lines[r].normal.allFinite()) { rows_ = 0; return false; }
  if (!layout(n, image.colour())) { rows_ = 0; return false; }
  lines_.assign(lines, lines + n);
  const int w = image.width_px(), h = image.height_px(), cols = width_px_;
  const float* px = image.pixels();
  float* planes[kCueChannels] = {window_.plane(CueChannel::Intensity), window_.plane(CueChannel::ChromaR),
                                 window_.plane(CueChannel::ChromaG), window_.plane(CueChannel::Texture)};
  const float xmax = static_cast<float>(w - 1) - 1e-3f, ymax = static_cast<float>(h - 1) - 1e-3f;
  const float half = 0.5f * static_cast<float>(cols - 1);
  const std::size_t stride = 4 * static_cast<std::size_t>(w);
  for (int r = 0; r < n; ++r) {
    const float cx = static_cast<float>(lines[r].centre_px.x()), cy = static_cast<float>(lines[r].centre_px.y());
    const float nx = static_cast<float>(lines[r].normal.x()), ny = static_cast<float>(lines[r].normal.y());
    const int base = r * cols;
    // A row is a segment: inside the image (with the +1 bilinear neighbour) when both ends are,
    // and then needs no clamp per pixel.
    const float xa = cx - half * nx, ya = cy - half * ny, xb = cx + half * nx, yb = cy + half * ny;
    image.prepare_span(xa, ya, xb, yb);
    const bool inside = std::min(xa, xb) >= 0 && std::min(ya, yb) >= 0 && std::max(xa, xb) < xmax && std::max(ya, yb) < ymax;
    int c = 0;
#if defined(__SSE4_1__)
    // Four pixels per pass: four all-channel taps (one register each: I, R, G, T), then a 4x4
    // transpose into the four planes; the same arithmetic as the scalar tap below.
    for (; c + 4 <= cols; c += 4) {
      __m128 v[4];
      for (int k = 0; k < 4; ++k) {
        const float off = static_cast<float>(c + k) - half;
        float x = cx + off * nx, y = cy + off * ny;
        if (!inside) {
          x = std::clamp(x, 0.0f, xmax);
          y = std::clamp(y, 0.0f, ymax);
        }
        const int ix = static_cast<int>(x), iy = static_cast<int>(y);
        const __m128 fx = _mm_set1_ps(x - static_cast<float>(ix)), fy = _mm_set1_ps(y - static_cast<float>(iy));
        const float* q0 = px + 4 * (static_cast<std::size_t>(iy) * w + ix);
        const float* q1 = q0 + stride;
        const __m128 a0 = _mm_loadu_ps(q0), b0 = _mm_loadu_ps(q0 + 4), a1 = _mm_loadu_ps(q1), b1 = _mm_loadu_ps(q1 + 4);
        const __m128 top = _mm_add_ps(a0, _mm_mul_ps(fx, _mm_sub_ps(b0, a0)));
        const __m128 bottom = _mm_add_ps(a1, _mm_mul_ps(fx, _mm_sub_ps(b1, a1)));
        v[k] = _mm_add_ps(top, _mm_mul_ps(fy, _mm_sub_ps(bottom, top)));
      }
      _MM_TRANSPOSE4_PS(v[0], v[1], v[2], v[3]);
      for (int k = 0; k < 4; ++k) _mm_storeu_ps(planes[k] + base + c, v[k]);
    }
#endif
    for (; c < cols; ++c) {
      const float off = static_cast<float>(c) - half;
      // Clamped coordinates repeat the border (such rows simply find no edge there).
      float x = cx + off * nx, y = cy + off * ny;
      if (!inside) {
        x = std::clamp(x, 0.0f, xmax);
        y = std::clamp(y, 0.0f, ymax);
      }
      const int ix = static_cast<int>(x), iy = static_cast<int>(y);
      const float fx = x - static_cast<float>(ix), fy = y - static_cast<float>(iy);
      const float* q0 = px + 4 * (static_cast<std::size_t>(iy) * w + ix);
      const float* q1 = q0 + stride;
      for (int k = 0; k < kCueChannels; ++k) {
        const float top = q0[k] + fx * (q0[4 + k] - q0[k]), bottom = q1[k] + fx * (q1[4 + k] - q1[k]);
        planes[k][base + c] = top + fy * (bottom - top);
      }
    }
  }
  return true;
}

Eigen::Vector2d TrackerLineWindow::to_image(int row, double x_px) const {
  const TrackerLine& l = lines_[static_cast<std::size_t>(row)];
  return l.centre_px + x_px * l.normal;
}

}  // namespace epichead::vision
