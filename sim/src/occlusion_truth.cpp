#include "epichead/sim/occlusion_truth.h"

#include <algorithm>

#include "occluder_motion.h"

namespace epichead::sim {
namespace {

// The segment from `from` to `to` crosses the triangle (a, b, c) strictly between its ends
// (Moller-Trumbore; both sides of the triangle count).
bool segment_hits_triangle(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Eigen::Vector3d& a,
                           const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d dir = to - from, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = dir.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-15) return false;  // parallel to the triangle's plane
  const double inv = 1 / det;
  const Eigen::Vector3d s = from - a;
  const double u = s.dot(p) * inv;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = dir.dot(q) * inv;
  if (v < 0 || u + v > 1) return false;
  const double t = e2.dot(q) * inv;  // along the segment, 0 at `from`, 1 at `to`
  return t > 1e-9 && t < 1 - 1e-9;
}

bool segment_hits_mesh(const Eigen::Vector3d& from, const Eigen::Vector3d& to, const Mesh& mesh) {
  for (const auto& tri : mesh.triangles) {
    const auto& a = mesh.positions[static_cast<std::size_t>(tri[0])];
    const auto& b = mesh.positions[static_cast<std::size_t>(tri[1])];
    const auto& c = mesh.positions[static_cast<std::size_t>(tri[2])];
    if (segment_hits_triangle(from, to, a.cast<double>(), b.cast<double>(), c.cast<double>())) return true;
  }
  return false;
}

}  // namespace

OcclusionTruth::OcclusionTruth(const Scene& scene, const Scenario& scenario) {
  occluders_.occluders = scene.occluders;
  occluders_.occluder_paths = scene.occluder_paths;
  keys_.occluder_keys = scenario.occluder_keys;
  // Flat faces repeat their corners: keep each vertex once.
  std::vector<Eigen::Vector3f> corners = scene.object_mesh.positions;
  const auto less = [](const Eigen::Vector3f& p, const Eigen::Vector3f& q) {
    return std::lexicographical_compare(p.data(), p.data() + 3, q.data(), q.data() + 3);
  };
  std::sort(corners.begin(), corners.end(), less);
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  object_world_.reserve(corners.size());
  for (const auto& p : corners) object_world_.push_back(scene.world_T_obj * p.cast<double>());
}

bool OcclusionTruth::hides_object(double t_s, const Eigen::Isometry3d& world_T_cam) {
  if (occluders_.occluders.empty() || object_world_.empty()) return false;
  occluder_poses_at(occluders_, keys_, t_s, poses_);
  for (Eigen::Isometry3d& pose : poses_) pose = pose.inverse();  // occluder_T_world: segments into its frame
  const Eigen::Vector3d eye_world = world_T_cam.translation();
  for (const Eigen::Vector3d& p_world : object_world_) {
    bool covered = false;
    for (std::size_t j = 0; j < occluders_.occluders.size() && !covered; ++j)
      covered = segment_hits_mesh(poses_[j] * eye_world, poses_[j] * p_world, occluders_.occluders[j]);
    if (!covered) return false;  // this point is in sight (or hidden only by the object itself)
  }
  return true;
}

}  // namespace epichead::sim
