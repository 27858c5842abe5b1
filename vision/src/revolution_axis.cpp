#include "epichead/vision/revolution_axis.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>

namespace epichead::vision {
namespace {

// Vertices of one ring: height along the axis, radius from it, and their angles.
struct Ring {
  double height_m = 0, radius_m = 0;
  std::vector<double> angles_rad;
};

bool on_axis(const RevolutionAxis& axis, const Eigen::Vector3d& p, const Eigen::Vector3d& dir, double tol_m) {
  const Eigen::Vector3d d = p - axis.point_obj;
  return (d - d.dot(axis.direction_obj) * axis.direction_obj).norm() <= tol_m &&
         dir.normalized().cross(axis.direction_obj).norm() <= 1e-3;
}

// True when the angles are n evenly spaced directions (any start), within tol_rad.
bool evenly_spaced(std::vector<double>& angles, double tol_rad) {
  std::sort(angles.begin(), angles.end());
  const double step = 2 * std::numbers::pi / static_cast<double>(angles.size());
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double next = i + 1 < angles.size() ? angles[i + 1] : angles[0] + 2 * std::numbers::pi;
    if (std::abs(next - angles[i] - step) > tol_rad) return false;
  }
  return true;
}

}  // namespace

std::optional<RevolutionAxis> find_revolution_axis(const CadModel& model, int min_ring_vertices) {
  RevolutionAxis axis;
  if (!model.circles.empty()) {
    axis.point_obj = model.circles.front().centre_obj;
    axis.direction_obj = model.circles.front().normal_obj.normalized();
  } else if (!model.cylinders.empty()) {
    axis.point_obj = model.cylinders.front().axis_a_obj;
    axis.direction_obj = (model.cylinders.front().axis_b_obj - model.cylinders.front().axis_a_obj).normalized();
  } else {
    return std::nullopt;
  }
  if (!axis.point_obj.allFinite() || !axis.direction_obj.allFinite()) return std::nullopt;
  double size_m = 0;
  for (const Eigen::Vector3d& v : model.vertices) size_m = std::max(size_m, (v - axis.point_obj).norm());
  for (const ModelCircle& c : model.circles) size_m = std::max(size_m, (c.centre_obj - axis.point_obj).norm() + c.radius_m);
  const double tol_m = 1e-4 * std::max(size_m, 1e-3);
  for (const ModelCircle& c : model.circles)
    if (!on_axis(axis, c.centre_obj, c.normal_obj, tol_m)) return std::nullopt;
  for (const ModelCylinder& c : model.cylinders)
    if (!on_axis(axis, c.axis_a_obj, c.axis_b_obj - c.axis_a_obj, tol_m) || !on_axis(axis, c.axis_b_obj, c.axis_b_obj - c.axis_a_obj, tol_m))
      return std::nullopt;

  // Rings of vertices about the axis (points on the axis itself, an apex, need no ring).
  const Eigen::Vector3d u = axis.direction_obj.unitOrthogonal(), w = axis.direction_obj.cross(u);
  std::vector<Ring> rings;
  for (const Eigen::Vector3d& v : model.vertices) {
    const Eigen::Vector3d d = v - axis.point_obj;
    const double h = d.dot(axis.direction_obj);
    const Eigen::Vector3d radial = d - h * axis.direction_obj;
    const double r = radial.norm();
    if (r <= tol_m) continue;
    auto ring = std::find_if(rings.begin(), rings.end(), [&](const Ring& g) {
      return std::abs(g.height_m - h) <= tol_m && std::abs(g.radius_m - r) <= tol_m;
    });
    if (ring == rings.end()) ring = rings.insert(rings.end(), Ring{h, r, {}});
    ring->angles_rad.push_back(std::atan2(radial.dot(w), radial.dot(u)));
  }
  for (Ring& g : rings) {
    if (static_cast<int>(g.angles_rad.size()) < min_ring_vertices) return std::nullopt;
    // Round-off of a vertex written with a few decimals moves it by ~tol_m, i.e. tol_m / r rad.
    if (!evenly_spaced(g.angles_rad, 2 * tol_m / g.radius_m + 1e-6)) return std::nullopt;
    const double n = static_cast<double>(g.angles_rad.size());
    axis.facet_sagitta_m = std::max(axis.facet_sagitta_m, g.radius_m * (1 - std::cos(std::numbers::pi / n)));
  }
  return axis;
}

Eigen::Matrix<double, 6, 1> revolution_twist(const RevolutionAxis& axis, const Eigen::Isometry3d& cam_T_obj) {
  // Turning about direction d through point c (camera frame) moves X to X + theta d x (X - c):
  // rotation part d, translation part -d x c = c x d.
  const Eigen::Vector3d d = cam_T_obj.linear() * axis.direction_obj;
  const Eigen::Vector3d c = cam_T_obj * axis.point_obj;
  Eigen::Matrix<double, 6, 1> xi;
  xi << c.cross(d), d;
  return xi;
}

}  // namespace epichead::vision
