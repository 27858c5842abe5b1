#pragma once
// Private to the renderer: the undistorted "ideal" pinhole image everything is drawn in, and
// clipping of camera-frame polygons against its near plane and guard band (shared by the object
// rasteriser and the environment layer).
#include <Eigen/Core>

namespace epichead::sim::render {

// A vertex in the camera frame with its attributes, before and during clipping.
struct Vertex {
  Eigen::Vector3f p;
  float shade = 1, u = 0, v = 0;
};

inline Vertex lerp(const Vertex& a, const Vertex& b, float s) {
  return {a.p + s * (b.p - a.p), a.shade + s * (b.shade - a.shade), a.u + s * (b.u - a.u), a.v + s * (b.v - a.v)};
}

// A clip plane n . p + d >= 0 in the camera frame.
struct ClipPlane {
  Eigen::Vector3f n;
  float d;
  float eval(const Eigen::Vector3f& p) const { return n.dot(p) + d; }
};

// Sutherland-Hodgman against one plane; `out` must hold n_in + 1 vertices.
inline int clip_polygon(const Vertex* in, int n_in, const ClipPlane& plane, Vertex* out) {
  int n_out = 0;
  for (int i = 0; i < n_in; ++i) {
    const Vertex& a = in[i];
    const Vertex& b = in[(i + 1) % n_in];
    const float da = plane.eval(a.p), db = plane.eval(b.p);
    if (da >= 0) out[n_out++] = a;
    if ((da >= 0) != (db >= 0)) out[n_out++] = lerp(a, b, da / (da - db));
  }
  return n_out;
}

// The ideal image: its size, pinhole intrinsics and the clip planes that keep projected
// coordinates in range (near plane, and a guard band far outside the image).
struct IdealView {
  static constexpr double kGuardBandPx = 4096;
  int W = 0, H = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  ClipPlane clip_planes[5];

  void set_clip_planes(double near_m) {
    const float gx = static_cast<float>(kGuardBandPx / fx), gy = static_cast<float>(kGuardBandPx / fy);
    const float xl = static_cast<float>(-cx / fx) - gx, xr = static_cast<float>((W - cx) / fx) + gx;
    const float yt = static_cast<float>(-cy / fy) - gy, yb = static_cast<float>((H - cy) / fy) + gy;
    clip_planes[0] = {{0, 0, 1}, -static_cast<float>(near_m)};
    clip_planes[1] = {{1, 0, -xl}, 0};  // x/z >= xl
    clip_planes[2] = {{-1, 0, xr}, 0};  // x/z <= xr
    clip_planes[3] = {{0, 1, -yt}, 0};
    clip_planes[4] = {{0, -1, yb}, 0};
  }
};

// A convex polygon projected into the ideal image after clipping.
struct ScreenPolygon {
  static constexpr int kMaxVertices = 12;
  Eigen::Vector2d v[kMaxVertices];
  int n = 0;
  int y0 = 0, y1 = 0;  // rows that may hold pixels of it: [y0, y1)

  // Clips the camera-frame polygon `corners` (n <= 4) and projects it; false when nothing of it
  // is in the image. `x0`, `x1` receive the column range [x0, x1) like y0, y1.
  bool project(const IdealView& view, const Eigen::Vector3f* corners, int n_corners, int& x0, int& x1);
  // The pixels of row y whose centres lie inside: [x0, x1]; false when none.
  bool row_span(int y, int W, int& x0, int& x1) const;
};

}  // namespace epichead::sim::render
