// Mesh builders and small pose helpers of the scene description.
#include "epichead/sim/scene.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "epichead/geometry/so3.h"

namespace epichead::sim {
namespace {

int add_vertex(Mesh& mesh, const Eigen::Vector3d& p, const Eigen::Vector3d& n) {
  mesh.positions.push_back(p.cast<float>());
  mesh.normals.push_back(n.normalized().cast<float>());
  return static_cast<int>(mesh.positions.size()) - 1;
}

void add_triangle(Mesh& mesh, int a, int b, int c, int material) {
  mesh.triangles.push_back({a, b, c});
  mesh.triangle_material.push_back(material);
}

// A flat convex polygon (CCW seen from where `normal` points) as a triangle fan.
void add_flat_polygon(Mesh& mesh, const std::vector<Eigen::Vector3d>& corners, const Eigen::Vector3d& normal,
                      int material) {
  const int first = static_cast<int>(mesh.positions.size());
  for (const auto& c : corners) add_vertex(mesh, c, normal);
  for (std::size_t i = 1; i + 1 < corners.size(); ++i)
    add_triangle(mesh, first, first + static_cast<int>(i), first + static_cast<int>(i) + 1, material);
}

}  // namespace

void add_quad(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
              const Eigen::Vector3d& d, int material) {
  const Eigen::Vector3d n = (c - a).cross(d - b).normalized();
  add_flat_polygon(mesh, {a, b, c, d}, n, material);
}

void add_box(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, const Eigen::Vector3d& size_m, int material) {
  const Eigen::Vector3d h = size_m / 2;
  auto corner = [&](int sx, int sy, int sz) {
    return Eigen::Vector3d(frame_T_part * Eigen::Vector3d(sx * h.x(), sy * h.y(), sz * h.z()));
  };
  // Each face CCW seen from outside.
  add_quad(mesh, corner(1, -1, -1), corner(1, 1, -1), corner(1, 1, 1), corner(1, -1, 1), material);       // +x
  add_quad(mesh, corner(-1, 1, -1), corner(-1, -1, -1), corner(-1, -1, 1), corner(-1, 1, 1), material);   // -x
  add_quad(mesh, corner(1, 1, -1), corner(-1, 1, -1), corner(-1, 1, 1), corner(1, 1, 1), material);       // +y
  add_quad(mesh, corner(-1, -1, -1), corner(1, -1, -1), corner(1, -1, 1), corner(-1, -1, 1), material);   // -y
  add_quad(mesh, corner(-1, -1, 1), corner(1, -1, 1), corner(1, 1, 1), corner(-1, 1, 1), material);       // +z
  add_quad(mesh, corner(-1, 1, -1), corner(1, 1, -1), corner(1, -1, -1), corner(-1, -1, -1), material);   // -z
}

void add_frustum(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, double radius_a_m, double radius_b_m,
                 double height_m, int segments, Caps caps, int material) {
  segments = std::max(segments, 3);
  const Eigen::Matrix3d R = frame_T_part.linear();
  // The surface normal of a cone tilts along the axis by the slope of its side.
  const double slope = (radius_a_m - radius_b_m) / height_m;
  const int first = static_cast<int>(mesh.positions.size());
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * std::numbers::pi * i / segments;
    const Eigen::Vector3d radial(std::cos(a), std::sin(a), 0);
    const Eigen::Vector3d n = R * (radial + Eigen::Vector3d(0, 0, slope));
    add_vertex(mesh, frame_T_part * Eigen::Vector3d(radius_a_m * radial), n);
    add_vertex(mesh, frame_T_part * Eigen::Vector3d(radius_b_m * radial + Eigen::Vector3d(0, 0, height_m)), n);
  }
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    const int a0 = first + 2 * i, b0 = a0 + 1, a1 = first + 2 * j, b1 = a1 + 1;
    add_triangle(mesh, a0, a1, b1, material);
    add_triangle(mesh, a0, b1, b0, material);
  }
  if (caps == Caps::Both) {
    Eigen::Isometry3d bottom = frame_T_part * Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
    add_disc(mesh, bottom, radius_a_m, 0, segments, material);
    Eigen::Isometry3d top = frame_T_part * Eigen::Translation3d(0, 0, height_m);
    add_disc(mesh, top, radius_b_m, 0, segments, material);
  }
}

void add_disc(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, double radius_m, double inner_radius_m,
              int segments, int material) {
  segments = std::max(segments, 3);
  const Eigen::Vector3d n = frame_T_part.linear() * Eigen::Vector3d::UnitZ();
  const int first = static_cast<int>(mesh.positions.size());
  if (inner_radius_m <= 0) {
    add_vertex(mesh, frame_T_part.translation(), n);
    for (int i = 0; i < segments; ++i) {
      const double a = 2 * std::numbers::pi * i / segments;
      add_vertex(mesh, frame_T_part * Eigen::Vector3d(radius_m * std::cos(a), radius_m * std::sin(a), 0), n);
    }
    for (int i = 0; i < segments; ++i)
      add_triangle(mesh, first, first + 1 + i, first + 1 + (i + 1) % segments, material);
    return;
  }
  for (int i = 0; i < segments; ++i) {
    const double a = 2 * std::numbers::pi * i / segments;
    const Eigen::Vector3d dir(std::cos(a), std::sin(a), 0);
    add_vertex(mesh, frame_T_part * Eigen::Vector3d(inner_radius_m * dir), n);
    add_vertex(mesh, frame_T_part * Eigen::Vector3d(radius_m * dir), n);
  }
  for (int i = 0; i < segments; ++i) {
    const int j = (i + 1) % segments;
    const int i0 = first + 2 * i, o0 = i0 + 1, i1 = first + 2 * j, o1 = i1 + 1;
    add_triangle(mesh, i0, o0, o1, material);
    add_triangle(mesh, i0, o1, i1, material);
  }
}

Mesh mesh_from_model(const vision::CadModel& model, const std::vector<int>& face_material, int cylinder_segments) {
  Mesh mesh;
  mesh.closed = model.closed;
  auto material_of = [&](std::size_t face) {
    if (face_material.empty()) return 0;
    return face < face_material.size() ? face_material[face] : face_material.front();
  };
  for (std::size_t f = 0; f < model.faces.size(); ++f) {
    const auto& face = model.faces[f];
    const int first = static_cast<int>(mesh.positions.size());
    // Map the model's vertex indices to this face's own copies (flat normal per face).
    for (int v : face.vertices) add_vertex(mesh, model.vertices[static_cast<std::size_t>(v)], face.normal_obj);
    for (const auto& tri : face.triangles) {
      std::array<int, 3> local{};
      for (int k = 0; k < 3; ++k) {
        const auto it = std::find(face.vertices.begin(), face.vertices.end(), tri[static_cast<std::size_t>(k)]);
        local[static_cast<std::size_t>(k)] = first + static_cast<int>(it - face.vertices.begin());
      }
      // Keep every triangle counter-clockwise from outside whatever the triangulation did.
      const Eigen::Vector3f& a = mesh.positions[static_cast<std::size_t>(local[0])];
      const Eigen::Vector3f& b = mesh.positions[static_cast<std::size_t>(local[1])];
      const Eigen::Vector3f& c = mesh.positions[static_cast<std::size_t>(local[2])];
      if ((b - a).cross(c - a).dot(face.normal_obj.cast<float>()) < 0) std::swap(local[1], local[2]);
      add_triangle(mesh, local[0], local[1], local[2], material_of(f));
    }
  }
  for (const auto& cyl : model.cylinders) {
    const Eigen::Vector3d axis = cyl.axis_b_obj - cyl.axis_a_obj;
    const double length = axis.norm();
    if (length <= 0 || cyl.radius_m <= 0) continue;
    Eigen::Isometry3d frame_T_part = Eigen::Isometry3d::Identity();
    frame_T_part.linear() = geometry::rotation_between(Eigen::Vector3d::UnitZ(), axis / length);
    frame_T_part.translation() = cyl.axis_a_obj;
    add_frustum(mesh, frame_T_part, cyl.radius_m, cyl.radius_m, length, cylinder_segments, Caps::Both,
                material_of(model.faces.size() + static_cast<std::size_t>(&cyl - model.cylinders.data())));
  }
  return mesh;
}

Eigen::Isometry3d occluder_pose(const OccluderPath& path, double t_s) {
  double s = 0;
  if (t_s > path.start_s && path.period_s > 0) {
    const double phase = std::fmod(t_s - path.start_s, path.period_s) / path.period_s;
    s = phase < 0.5 ? 2 * phase : 2 - 2 * phase;
  }
  const Eigen::Quaterniond q0(path.world_T_start.linear()), q1(path.world_T_end.linear());
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = q0.slerp(s, q1).toRotationMatrix();
  out.translation() = (1 - s) * path.world_T_start.translation() + s * path.world_T_end.translation();
  return out;
}

}  // namespace epichead::sim
