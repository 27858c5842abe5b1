#include "render_clip.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace epichead::sim::render {

bool ScreenPolygon::project(const IdealView& view, const Eigen::Vector3f* corners, int n_corners, int& x0, int& x1) {
  Vertex a[kMaxVertices], b[kMaxVertices];  // 4 corners + one per clip plane at most
  for (int i = 0; i < n_corners; ++i) a[i].p = corners[i];
  Vertex* in = a;
  Vertex* o = b;
  int count = n_corners;
  for (const auto& plane : view.clip_planes) {
    count = clip_polygon(in, count, plane, o);
    if (count < 3) return false;
    std::swap(in, o);
  }
  n = count;
  float xmin = 1e30f, ymin = 1e30f, xmax = -1e30f, ymax = -1e30f;
  for (int i = 0; i < count; ++i) {
    const float x = static_cast<float>(view.fx) * in[i].p.x() / in[i].p.z() + static_cast<float>(view.cx);
    const float y = static_cast<float>(view.fy) * in[i].p.y() / in[i].p.z() + static_cast<float>(view.cy);
    if (!std::isfinite(x) || !std::isfinite(y)) return false;
    v[i] = {x, y};
    xmin = std::min(xmin, x); xmax = std::max(xmax, x); ymin = std::min(ymin, y); ymax = std::max(ymax, y);
  }
  x0 = std::max(0, static_cast<int>(std::floor(xmin)) - 1);
  y0 = std::max(0, static_cast<int>(std::floor(ymin)) - 1);
  x1 = std::min(view.W, static_cast<int>(std::ceil(xmax)) + 2);
  y1 = std::min(view.H, static_cast<int>(std::ceil(ymax)) + 2);
  return x0 < x1 && y0 < y1;
}

bool ScreenPolygon::row_span(int y, int W, int& x0, int& x1) const {
  double lo = 1e300, hi = -1e300;
  const double yc = y;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d& a = v[i];
    const Eigen::Vector2d& b = v[(i + 1) % n];
    if ((a.y() <= yc) == (b.y() <= yc)) continue;
    const double x = a.x() + (yc - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    lo = std::min(lo, x);
    hi = std::max(hi, x);
  }
  if (!(lo <= hi)) return false;
  x0 = static_cast<int>(std::max(0.0, std::ceil(lo)));
  x1 = static_cast<int>(std::min(static_cast<double>(W - 1), std::ceil(hi) - 1));
  return x0 <= x1;
}

}  // namespace epichead::sim::render
