#include "epichead/vision/rim_side.h"

#include <cmath>

namespace epichead::vision {
namespace {

// Ray casting in the face's plane: is p inside the polygon (object frame, projected on the plane)?
bool inside_face(const CadModel& model, const ModelFace& face, const Eigen::Vector3d& p) {
  const Eigen::Vector3d n = face.normal_obj;
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  bool in = false;
  const std::size_t k = face.vertices.size();
  for (std::size_t i = 0, j = k - 1; i < k; j = i++) {
    const Eigen::Vector3d& a = model.vertices[static_cast<std::size_t>(face.vertices[i])];
    const Eigen::Vector3d& b = model.vertices[static_cast<std::size_t>(face.vertices[j])];
    const double ax = a.dot(u), ay = a.dot(v), bx = b.dot(u), by = b.dot(v), px = p.dot(u), py = p.dot(v);
    if ((ay > py) != (by > py) && px < (bx - ax) * (py - ay) / (by - ay) + ax) in = !in;
  }
  return in;
}

}  // namespace

RimSides::RimSides(const CadModel& model, const Camera& camera) : model_(&model), camera_(camera) {
  rims_.resize(model.circles.size());
  for (std::size_t c = 0; c < model.circles.size(); ++c) {
    const ModelCircle& circle = model.circles[c];
    const Eigen::Vector3d n = circle.normal_obj.normalized();
    const double tol = 1e-3 * circle.radius_m + 1e-6;
    Rim& rim = rims_[c];
    for (std::size_t f = 0; f < model.faces.size(); ++f) {
      const ModelFace& face = model.faces[f];
      if (face.vertices.size() < 3 || face.normal_obj.isZero()) continue;
      const bool in_plane = std::abs(std::abs(face.normal_obj.dot(n)) - 1) < 1e-6 &&
                            std::abs(face.normal_obj.dot(circle.centre_obj) - face.offset_m) < tol;
      if (in_plane) {
        if (inside_face(model, face, circle.centre_obj)) {
          rim.cap = static_cast<int>(f);
          rim.cap_normal_obj = face.normal_obj;
        }
        continue;
      }
      // A side face: its vertices on the circle, and the direction from there into the face.
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int vi : face.vertices) centroid += model.vertices[static_cast<std::size_t>(vi)];
      centroid /= static_cast<double>(face.vertices.size());
      for (int vi : face.vertices) {
        const Eigen::Vector3d& p = model.vertices[static_cast<std::size_t>(vi)];
        if (!on_circle(circle, p)) continue;
        const Eigen::Vector3d into = centroid - p;
        if (into.norm() <= tol) continue;
        rim.sides.push_back({p, into.normalized(), face.normal_obj});
      }
    }
  }
}

void RimSides::apply(const Eigen::Isometry3d& cam_T_obj, VisibleModel& visible) const {
  const Eigen::Matrix3d R = cam_T_obj.linear();
  for (VisibleEllipse& e : visible.ellipses) {
    e.side = ObjectSide::Both;
    if (e.circle < 0 || static_cast<std::size_t>(e.circle) >= rims_.size()) continue;
    const Rim& rim = rims_[static_cast<std::size_t>(e.circle)];
    const ModelCircle& circle = model_->circles[static_cast<std::size_t>(e.circle)];
    const Eigen::Vector3d centre_cam = cam_T_obj * circle.centre_obj;
    const bool cap_seen = rim.cap >= 0 && (R * rim.cap_normal_obj).dot(-centre_cam) > 0;
    int seen = 0, inside = 0, outside = 0;
    for (const SideFace& s : rim.sides) {
      const Eigen::Vector3d p_cam = cam_T_obj * s.rim_point_obj;
      // Faces of a closed model are seen from outside only; an open surface (a lamp shade)
      // shows its inner side too.
      const bool face_seen = !model_->closed || (R * s.normal_obj).dot(-p_cam) > 0;
      if (!(p_cam.z() > 0) || (!face_seen && !cap_seen)) continue;
      ++seen;
      bool in = cap_seen, out = false;
      if (face_seen) {
        const Eigen::Vector3d q_cam = p_cam + R * s.into_obj * (0.01 * circle.radius_m);
        if (!(q_cam.z() > 0)) continue;
        const Eigen::Vector2d p = camera_.project(p_cam), d = camera_.project(q_cam) - p;
        ((d.dot(p - e.centre_px) < 0) ? in : out) = true;
      }
      inside += in;
      outside += out;
    }
    if (seen == 0) {
      if (rim.sides.empty() && cap_seen) e.side = ObjectSide::Left;  // a disc alone
      continue;
    }
    if (inside == seen && outside < seen) e.side = ObjectSide::Left;
    else if (outside == seen && inside < seen) e.side = ObjectSide::Right;
  }
}

}  // namespace epichead::vision
