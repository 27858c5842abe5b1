// ViSP's CAO model format (V1): the writer (the reader: cao_reader.cpp). Numbers are written as
// the shortest text that reads back exactly, so a model written and read again is the same.
#include <array>
#include <charconv>
#include <cmath>
#include <map>
#include <string>
#include <system_error>
#include <vector>

#include <Eigen/Geometry>

#include "epichead/vision/cao_model.h"

namespace epichead::vision {
namespace {

void put_number(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest text that reads back exactly
  out.append(buf, ec == std::errc{} ? end : buf);
}

}  // namespace

std::string to_cao(const CadModel& model) {
  // Circles and cylinders refer to points: reuse model vertices at exactly the same place (so
  // a model read from a file reads back with the same vertices), else append points.
  std::vector<Eigen::Vector3d> points = model.vertices;
  std::map<std::array<double, 3>, int> where;
  for (std::size_t i = 0; i < points.size(); ++i) {
    where.try_emplace({points[i].x(), points[i].y(), points[i].z()}, static_cast<int>(i));
  }
  auto point_at = [&](const Eigen::Vector3d& p) {
    const auto [it, added] = where.try_emplace({p.x(), p.y(), p.z()}, static_cast<int>(points.size()));
    if (added) points.push_back(p);
    return it->second;
  };
  std::vector<std::array<int, 2>> cylinders;
  for (const ModelCylinder& c : model.cylinders) cylinders.push_back({point_at(c.axis_a_obj), point_at(c.axis_b_obj)});
  std::vector<std::array<int, 3>> circles;
  for (const ModelCircle& c : model.circles) {
    const int centre = point_at(c.centre_obj);
    const Eigen::Vector3d n = c.normal_obj.normalized();
    // Two vertices already in the circle's plane whose cross product gives its normal, if any
    // (a few candidates only: this is for models read from CAO, where they exist).
    int p1 = -1, p2 = -1;
    int tries = 0;
    for (std::size_t a = 0; a < model.vertices.size() && p1 < 0 && tries < 8; ++a) {
      const Eigen::Vector3d da = model.vertices[a] - c.centre_obj;
      if (!(da.norm() > 0) || std::abs(n.dot(da)) > 1e-9 * da.norm()) continue;
      ++tries;
      for (std::size_t b = 0; b < model.vertices.size(); ++b) {
        const Eigen::Vector3d cross = da.cross(model.vertices[b] - c.centre_obj);
        if (cross.norm() > 0 && n.dot(cross.normalized()) > 1 - 1e-14) {
          p1 = static_cast<int>(a);
          p2 = static_cast<int>(b);
          break;
        }
      }
    }
    if (p1 < 0) {
      const Eigen::Vector3d u = n.unitOrthogonal();
      p1 = point_at(c.centre_obj + c.radius_m * u);
      p2 = point_at(c.centre_obj + c.radius_m * n.cross(u));
    }
    circles.push_back({centre, p1, p2});
  }

  std::string out = "V1\n# Written by epichead\n# 3D Points\n" + std::to_string(points.size()) + "\n";
  for (const Eigen::Vector3d& p : points) {
    put_number(out, p.x());
    out += ' ';
    put_number(out, p.y());
    out += ' ';
    put_number(out, p.z());
    out += '\n';
  }
  std::string lines;
  std::size_t line_count = 0;
  for (const ModelEdge& e : model.edges) {
    if (e.face_count() != 0 || e.extra_faces != 0) continue;
    lines += std::to_string(e.v0) + " " + std::to_string(e.v1) + "\n";
    ++line_count;
  }
  out += "# 3D Lines\n" + std::to_string(line_count) + "\n" + lines;
  out += "# Faces from 3D lines\n0\n# Faces from 3D points\n" + std::to_string(model.faces.size()) + "\n";
  for (const ModelFace& f : model.faces) {
    out += std::to_string(f.vertices.size());
    for (int v : f.vertices) out += " " + std::to_string(v);
    out += '\n';
  }
  out += "# 3D cylinders\n" + std::to_string(cylinders.size()) + "\n";
  for (std::size_t i = 0; i < cylinders.size(); ++i) {
    out += std::to_string(cylinders[i][0]) + " " + std::to_string(cylinders[i][1]) + " ";
    put_number(out, model.cylinders[i].radius_m);
    out += '\n';
  }
  out += "# 3D circles\n" + std::to_string(circles.size()) + "\n";
  for (std::size_t i = 0; i < circles.size(); ++i) {
    put_number(out, model.circles[i].radius_m);
    out += " " + std::to_string(circles[i][0]) + " " + std::to_string(circles[i][1]) + " " +
           std::to_string(circles[i][2]) + "\n";
  }
  return out;
}

}  // namespace epichead::vision
