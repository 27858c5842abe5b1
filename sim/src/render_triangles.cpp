// Triangle set-up for the object pass: each posed mesh's triangles moved into the camera frame,
// back faces of closed meshes culled, lit per vertex, clipped to the near plane and guard band,
// projected to fixed point and given their attribute planes.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "renderer_impl.h"

namespace epichead::sim {
namespace {

using render::ceil_div;
using render::clip_polygon;
using render::floor_div;
using render::FrameMaterial;
using render::kFixOne;
using render::RasterTriangle;
using render::Vertex;

}  // namespace

// Transforms, culls, lights, clips and sets up the triangles of one posed mesh.
void Renderer::Impl::add_mesh(const Mesh& mesh, const Eigen::Isometry3d& cam_T_mesh, const Eigen::Isometry3d& world_T_mesh) {
  const Eigen::Matrix3f R = cam_T_mesh.linear().cast<float>();
  const Eigen::Vector3f t = cam_T_mesh.translation().cast<float>();
  if (!R.allFinite() || !t.allFinite()) return;
  const Eigen::Vector3f light = (world_T_mesh.linear().transpose() * scene.light.direction_world.normalized()).cast<float>();
  const float ambient = static_cast<float>(scene.light.ambient), diffuse = static_cast<float>(scene.light.diffuse);
  // Camera centre in the mesh frame: back-facing test without transforming normals.
  const Eigen::Vector3f eye = -(R.transpose() * t);
  for (std::size_t ti = 0; ti < mesh.triangles.size(); ++ti) {
    const auto& tri = mesh.triangles[ti];
    const Eigen::Vector3f& p0 = mesh.positions[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3f& p1 = mesh.positions[static_cast<std::size_t>(tri[1])];
    const Eigen::Vector3f& p2 = mesh.positions[static_cast<std::size_t>(tri[2])];
    const Eigen::Vector3f n_geo = (p1 - p0).cross(p2 - p0);
    const bool front = n_geo.dot(eye - p0) > 0;
    if (!front && mesh.closed) continue;
    const int mat = mesh.triangle_material[ti];
    const FrameMaterial& fm = materials[static_cast<std::size_t>(mat)];
    Vertex v[3];
    for (int k = 0; k < 3; ++k) {
      const auto idx = static_cast<std::size_t>(tri[static_cast<std::size_t>(k)]);
      const Eigen::Vector3f& p = mesh.positions[idx];
      // The lit side of an open surface is the side the camera sees.
      const float ndotl = (front ? 1.f : -1.f) * mesh.normals[idx].dot(light);
      const float lighting = ambient + diffuse * std::max(0.f, ndotl);
      float reflect = fm.time_factor * std::max(0.f, 1 + fm.gradient.dot(p - fm.gradient_origin));
      reflect = std::min(reflect, 1.f / fm.albedo_max);
      v[k].p = R * p + t;
      v[k].shade = lighting * reflect;
      if (fm.texture >= 0) {
        v[k].u = fm.tex_u.dot(p - fm.tex_origin) - 0.5f;
        v[k].v = fm.tex_v.dot(p - fm.tex_origin) - 0.5f;
      }
    }
    if (!(v[0].p.allFinite() && v[1].p.allFinite() && v[2].p.allFinite())) continue;
    add_clipped(v, mat);
  }
}

void Renderer::Impl::add_clipped(const Vertex (&v)[3], int mat) {
  // Fast path: the triangle is inside every clip plane.
  bool inside = true;
  for (const auto& plane : clip_planes)
    for (const auto& vert : v) inside = inside && plane.eval(vert.p) >= 0;
  if (inside) { add_projected(v[0], v[1], v[2], mat); return; }
  Vertex a[8], b[8];
  int n = 3;
  std::copy(v, v + 3, a);
  Vertex* in = a;
  Vertex* out = b;
  for (const auto& plane : clip_planes) {
    n = clip_polygon(in, n, plane, out);
    if (n < 3) return;
    std::swap(in, out);
  }
  for (int i = 1; i + 1 < n; ++i) add_projected(in[0], in[i], in[i + 1], mat);
}

void Renderer::Impl::add_projected(const Vertex& a, const Vertex& b, const Vertex& c, int mat) {
  const Vertex* vs[3] = {&a, &b, &c};
  RasterTriangle t{};
  double w[3];
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3f& p = vs[k]->p;
    w[k] = 1.0 / p.z();
    t.X[k] = std::llround((fx * p.x() * w[k] + cx) * kFixOne);
    t.Y[k] = std::llround((fy * p.y() * w[k] + cy) * kFixOne);
  }
  std::int64_t area = (t.X[1] - t.X[0]) * (t.Y[2] - t.Y[0]) - (t.Y[1] - t.Y[0]) * (t.X[2] - t.X[0]);
  if (area == 0) return;
  int order[3] = {0, 1, 2};
  if (area < 0) { std::swap(order[1], order[2]); area = -area; }
  RasterTriangle r{};
  for (int k = 0; k < 3; ++k) { r.X[k] = t.X[order[k]]; r.Y[k] = t.Y[order[k]]; }
  const std::int64_t min_x = std::min({r.X[0], r.X[1], r.X[2]}), max_x = std::max({r.X[0], r.X[1], r.X[2]});
  const std::int64_t min_y = std::min({r.Y[0], r.Y[1], r.Y[2]}), max_y = std::max({r.Y[0], r.Y[1], r.Y[2]});
  r.x0 = static_cast<int>(std::max<std::int64_t>(0, floor_div(min_x, kFixOne) - 1));
  r.y0 = static_cast<int>(std::max<std::int64_t>(0, floor_div(min_y, kFixOne) - 1));
  r.x1 = static_cast<int>(std::min<std::int64_t>(W - 1, ceil_div(max_x, kFixOne) + 1));
  r.y1 = static_cast<int>(std::min<std::int64_t>(H - 1, ceil_div(max_y, kFixOne) + 1));
  if (r.x0 > r.x1 || r.y0 > r.y1) return;
  for (int i = 0; i < 3; ++i) {
    const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
    const std::int64_t dx = r.X[a2] - r.X[a1], dy = r.Y[a2] - r.Y[a1];
    r.bias[i] = (dy > 0 || (dy == 0 && dx < 0)) ? 0 : -1;
  }
  // Attribute planes from the barycentric planes, in pixel units relative to (x0, y0).
  // (Snapped vertices, so that the planes agree with the coverage test.)
  const double A = static_cast<double>(area) / static_cast<double>(kFixOne * kFixOne);
  double lx[3], ly[3], l0[3];
  for (int i = 0; i < 3; ++i) {
    const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
    const double x1 = static_cast<double>(r.X[a1]) / kFixOne, y1 = static_cast<double>(r.Y[a1]) / kFixOne;
    const double x2 = static_cast<double>(r.X[a2]) / kFixOne, y2 = static_cast<double>(r.Y[a2]) / kFixOne;
    lx[i] = -(y2 - y1) / A;
    ly[i] = (x2 - x1) / A;
    l0[i] = ((x2 - x1) * (r.y0 - y1) - (y2 - y1) * (r.x0 - x1)) / A;
  }
  auto plane = [&](const double (&val)[3], float (&out)[3]) {
    double a = 0, b = 0, c = 0;
    for (int i = 0; i < 3; ++i) {
      a += lx[i] * val[order[i]];
      b += ly[i] * val[order[i]];
      c += l0[i] * val[order[i]];
    }
    out[0] = static_cast<float>(a); out[1] = static_cast<float>(b); out[2] = static_cast<float>(c);
  };
  double sw[3], uw[3], vw[3];
  for (int k = 0; k < 3; ++k) {
    sw[k] = vs[k]->shade * w[k];
    uw[k] = vs[k]->u * w[k];
    vw[k] = vs[k]->v * w[k];
  }
  plane(w, r.w);
  plane(sw, r.s);
  plane(uw, r.u);
  plane(vw, r.v);
  r.material = mat;
  const FrameMaterial& fm = materials[static_cast<std::size_t>(mat)];
  if (fm.texture >= 0) {
    // Level from texels per pixel over the whole triangle: log4 of the area ratio.
    const double uv_area = std::abs((b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u));
    const double px_area = A;
    const int levels = static_cast<int>(tex_mips[static_cast<std::size_t>(fm.texture)].size());
    const double ratio = uv_area / std::max(px_area, 1e-12);
    r.mip = ratio > 1 ? std::min(levels - 1, static_cast<int>(0.5 * std::log2(ratio))) : 0;
  }
  tris.push_back(r);
}

}  // namespace epichead::sim
