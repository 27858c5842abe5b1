// Visibility of a CAD model from a pose.
//
// Every clipping step is done on the edge's 3D parameter s in [0, 1] (P(s) = A + s (B - A) in
// the camera frame): the near plane, the four planes of the image frustum, and occlusion by
// each model triangle are all constraints that are linear in s, so each gives an interval in
// closed form and an edge partly hidden by another face is cut into its visible pieces.
//
// Occlusion of P(s) by a triangle (V0, V1, V2), all in the camera frame:
//  - the ray from the optical centre through P(s) passes through the triangle iff P(s) lies in
//    the positive cone of V0, V1, V2: o * (Vi x Vj) . P(s) >= 0 for its three sides, with o the
//    sign of det(V0, V1, V2);
//  - the triangle is in front of P(s) iff P(s) and the optical centre are on opposite sides of
//    the triangle's plane n . X = d: d * (n . P(s) - d) > 0.
// Five linear constraints; their intersection is the hidden interval.
#include "epichead/vision/visibility.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace epichead::vision {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Interval [lo, hi] of s where g0 + s (g1 - g0) >= margin, intersected into [lo, hi].
inline void clip_linear(double g0, double g1, double margin, double& lo, double& hi) {
  const double slope = g1 - g0;
  const double a = g0 - margin;
  if (std::abs(slope) < 1e-300) {
    if (a < 0) { lo = 1; hi = 0; }
    return;
  }
  const double root = -a / slope;
  if (slope > 0) lo = std::max(lo, root);
  else hi = std::min(hi, root);
}

Eigen::Vector2d normalized(const Eigen::Vector3d& p) { return {p.x() / p.z(), p.y() / p.z()}; }

// Which side of the projected segment a->b (normalised coordinates, y down) the point q is on.
ObjectSide side_of(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
  const Eigen::Vector2d d = b - a;
  const Eigen::Vector2d w = q - a;
  const double cross = w.x() * d.y() - w.y() * d.x();  // w . (dy, -dx)
  // A face seen edge-on gives no reliable side.
  if (std::abs(cross) <= 1e-9 * d.squaredNorm()) return ObjectSide::Both;
  return cross > 0 ? ObjectSide::Left : ObjectSide::Right;
}

// The kind of a model edge at this pose, and which of its faces the object side is on (-1:
// both); false for an edge not drawn (between two faces turned away on a closed model, or
// between facets of a smooth surface). face_front: the camera is on a face's outer side;
// face_seen: ... within the view angle (closed models).
bool classify_edge(const CadModel& model, const ModelEdge& edge, const std::vector<unsigned char>& face_front,
                   const std::vector<unsigned char>& face_seen, double cos_crease, EdgeKind& kind, int& side_face) {
  const int fa = edge.faces[0], fb = edge.faces[1];
  side_face = -1;
  if (fa < 0 && fb < 0) {
    kind = EdgeKind::Wire;
  } else if (fa < 0 || fb < 0) {
    kind = EdgeKind::Boundary;
    side_face = fa >= 0 ? 0 : 1;
  } else {
    // Facets of a smooth surface keep the strict front test: their silhouette is where the
    // surface turns away, however grazing the last facet. Across a sharp edge a face seen
    // nearly edge-on counts as turned away (VisibilityOptions::max_view_angle_rad).
    const bool smooth = model.faces[fa].normal_obj.dot(model.faces[fb].normal_obj) > cos_crease;
    const bool front_a = smooth ? face_front[fa] : face_seen[fa];
    const bool front_b = smooth ? face_front[fb] : face_seen[fb];
    if (front_a != front_b) {
      kind = EdgeKind::Contour;
      side_face = front_a ? 0 : 1;
    } else {
      // Both toward the camera, or both away on an open model (thin sheets seen from behind).
      if (!front_a && model.closed) return false;
      if (smooth) return false;
      kind = EdgeKind::Crease;
    }
  }
  return true;
}

}  // namespace

Visibility::Visibility(const CadModel& model, const Camera& camera, const VisibilityOptions& options)
    : model_(&model), camera_(camera), options_(options) {
  for (int f = 0; f < static_cast<int>(model.faces.size()); ++f) {
    for (const auto& t : model.faces[f].triangles) {
      triangles_.push_back({model.vertices[t[0]], model.vertices[t[1]], model.vertices[t[2]], f});
    }
  }
  const std::size_t n = triangles_.size();
  vertices_cam_.resize(model.vertices.size());
  tri_cam_.resize(3 * n);
  tri_x0_.resize(n); tri_x1_.resize(n); tri_y0_.resize(n); tri_y1_.resize(n);
  candidates_.reserve(n);
  face_front_.resize(model.faces.size());
  face_seen_.resize(model.faces.size());
  hidden_.reserve(64);

  // The image frustum as the rectangle inscribed in the unprojected (undistorted) image border,
  // shrunk by the margin: what passes this clip projects inside the image.
  const double m = options_.margin_px;
  const double w = camera_.width_px() - 1 - m, h = camera_.height_px() - 1 - m;
  xn_min_ = -kInf; xn_max_ = kInf; yn_min_ = -kInf; yn_max_ = kInf;
  constexpr int kSteps = 32;
  for (int i = 0; i <= kSteps; ++i) {
    const double u = m + (w - m) * i / kSteps, v = m + (h - m) * i / kSteps;
    xn_min_ = std::max(xn_min_, camera_.pixel_to_normalized({m, v}).x());
    xn_max_ = std::min(xn_max_, camera_.pixel_to_normalized({w, v}).x());
    yn_min_ = std::max(yn_min_, camera_.pixel_to_normalized({u, m}).y());
    yn_max_ = std::min(yn_max_, camera_.pixel_to_normalized({u, h}).y());
  }
}

void Visibility::compute(const Eigen::Isometry3d& cam_T_obj, VisibleModel& out) {
  out.clear();
  const Eigen::Matrix3d R = cam_T_obj.linear();
  const Eigen::Vector3d t = cam_T_obj.translation();
  const Eigen::Vector3d camera_obj = -R.transpose() * t;
  classify_faces(camera_obj);
  for (std::size_t i = 0; i < model_->vertices.size(); ++i) vertices_cam_[i] = R * model_->vertices[i] + t;
  place_occluders(R, t);
  add_edges(R, t, out);
  add_limbs(R, t, camera_obj, out);
  add_circles(R, t, out);
}

void Visibility::classify_faces(const Eigen::Vector3d& camera_obj) {
  const CadModel& model = *model_;
  const double cos_max_view = std::max(0.0, std::cos(options_.max_view_angle_rad));
  for (std::size_t f = 0; f < model.faces.size(); ++f) {
    const auto& face = model.faces[f];
    const double height_m = face.normal_obj.dot(camera_obj) - face.offset_m;
    face_front_[f] = height_m > 0;
    // Seen within the angle where it is seen steepest, at its nearest vertex (cos = height /
    // distance, tested without the division): one decision per face, so all of its edges agree,
    // and a large face (a floor) that is steep near the camera counts as seen. Open models are
    // seen from both sides (thin sheets) and keep the strict test.
    bool seen = face_front_[f];
    if (seen && model.closed && cos_max_view > 0) {
      double nearest_m = std::numeric_limits<double>::infinity();
      for (int v : face.vertices) nearest_m = std::min(nearest_m, (camera_obj - model.vertices[v]).norm());
      seen = height_m > cos_max_view * nearest_m;
    }
    face_seen_[f] = seen;
  }
}

// Occluders. In a closed model a back face is always behind a front face, so front faces
// suffice; an open model's faces are thin sheets that hide from both sides.
void Visibility::place_occluders(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  const double near = options_.near_m;
  constexpr float kInfF = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < triangles_.size(); ++i) {
    const Triangle& tri = triangles_[i];
    // An empty box (x0 > x1) marks a triangle that hides nothing this call.
    tri_x0_[i] = kInfF; tri_x1_[i] = -kInfF; tri_y0_[i] = kInfF; tri_y1_[i] = -kInfF;
    if (model_->closed && !face_front_[tri.face]) continue;
    const Eigen::Vector3d p0 = R * tri.p0 + t, p1 = R * tri.p1 + t, p2 = R * tri.p2 + t;
    const double zmax = std::max({p0.z(), p1.z(), p2.z()});
    if (zmax <= near) continue;  // wholly behind the near plane: hides nothing in view
    tri_cam_[3 * i] = p0; tri_cam_[3 * i + 1] = p1; tri_cam_[3 * i + 2] = p2;
    if (std::min({p0.z(), p1.z(), p2.z()}) > near) {
      const Eigen::Vector2d a = normalized(p0), b = normalized(p1), c = normalized(p2);
      // Rounded outward so that float storage never shrinks the box.
      tri_x0_[i] = std::nextafter(static_cast<float>(std::min({a.x(), b.x(), c.x()})), -kInfF);
      tri_x1_[i] = std::nextafter(static_cast<float>(std::max({a.x(), b.x(), c.x()})), kInfF);
      tri_y0_[i] = std::nextafter(static_cast<float>(std::min({a.y(), b.y(), c.y()})), -kInfF);
      tri_y1_[i] = std::nextafter(static_cast<float>(std::max({a.y(), b.y(), c.y()})), kInfF);
    } else {
      // Crosses the near plane: no cheap bound.
      tri_x0_[i] = -kInfF; tri_x1_[i] = kInfF; tri_y0_[i] = -kInfF; tri_y1_[i] = kInfF;
    }
  }
}

// The interval [lo, hi] of the segment A->B (camera frame) in front of the near plane and inside
// the image frustum; false if empty.
bool Visibility::clip_to_view(const Eigen::Vector3d& A, const Eigen::Vector3d& B, double& lo, double& hi) const {
  lo = 0;
  hi = 1;
  clip_linear(A.z(), B.z(), options_.near_m, lo, hi);
  clip_linear(A.x() - xn_min_ * A.z(), B.x() - xn_min_ * B.z(), 0, lo, hi);
  clip_linear(xn_max_ * A.z() - A.x(), xn_max_ * B.z() - B.x(), 0, lo, hi);
  clip_linear(A.y() - yn_min_ * A.z(), B.y() - yn_min_ * B.z(), 0, lo, hi);
  clip_linear(yn_max_ * A.z() - A.y(), yn_max_ * B.z() - B.y(), 0, lo, hi);
  return hi > lo;
}

// hidden_: the sorted intervals of [lo, hi] of the segment hidden by a triangle of a face other
// than the segment's own; n0, n1 the clipped ends in normalised coordinates.
void Visibility::find_hidden(const Segment& seg, double lo, double hi, const Eigen::Vector2d& n0, const Eigen::Vector2d& n1,
                             double depth_margin_m) {
  const Eigen::Vector3d& A = seg.a_cam;
  const Eigen::Vector3d& B = seg.b_cam;
  const float bx0 = static_cast<float>(std::min(n0.x(), n1.x())), bx1 = static_cast<float>(std::max(n0.x(), n1.x()));
  const float by0 = static_cast<float>(std::min(n0.y(), n1.y())), by1 = static_cast<float>(std::max(n0.y(), n1.y()));

  // Box rejection over all triangles first: a branch-free loop over contiguous floats that
  // the compiler vectorises; only the few survivors get the exact test.
  candidates_.clear();
  const int count = static_cast<int>(triangles_.size());
  const float* x0 = tri_x0_.data(); const float* x1 = tri_x1_.data();
  const float* y0 = tri_y0_.data(); const float* y1 = tri_y1_.data();
  for (int i = 0; i < count; ++i) {
    if ((x0[i] <= bx1) & (x1[i] >= bx0) & (y0[i] <= by1) & (y1[i] >= by0)) candidates_.push_back(i);
  }
  hidden_.clear();
  for (const int i : candidates_) {
    const int face = triangles_[i].face;
    if (face == seg.face_a || face == seg.face_b) continue;
    const Eigen::Vector3d& V0 = tri_cam_[3 * i];
    const Eigen::Vector3d& V1 = tri_cam_[3 * i + 1];
    const Eigen::Vector3d& V2 = tri_cam_[3 * i + 2];
    const double det = V0.dot(V1.cross(V2));
    if (std::abs(det) < 1e-18) continue;  // seen edge-on: hides nothing
    const double o = det > 0 ? 1.0 : -1.0;
    double s0 = lo, s1 = hi;
    // Inside the cone, with a tolerance scaled to the geometry so that an edge running along
    // an occluder's border is not hidden by round-off.
    const Eigen::Vector3d c01 = o * V0.cross(V1), c12 = o * V1.cross(V2), c20 = o * V2.cross(V0);
    const double tol = 1e-9 * (std::abs(det) / (V0.norm() + V1.norm() + V2.norm() + 1e-30));
    clip_linear(c01.dot(A), c01.dot(B), tol, s0, s1);
    clip_linear(c12.dot(A), c12.dot(B), tol, s0, s1);
    clip_linear(c20.dot(A), c20.dot(B), tol, s0, s1);
    if (!(s1 > s0)) continue;
    // Behind the triangle's plane by more than a small depth tolerance (touching faces).
    const Eigen::Vector3d nrm = (V1 - V0).cross(V2 - V0);
    const double nn = nrm.norm();
    const Eigen::Vector3d nu = nrm / nn;
    const double d = nu.dot(V0);
    const double sgn = d > 0 ? 1.0 : -1.0;
    const double depth_tol = 1e-6 + 1e-7 * std::abs(d) + depth_margin_m;
    clip_linear(sgn * (nu.dot(A) - d), sgn * (nu.dot(B) - d), depth_tol, s0, s1);
    if (s1 > s0) hidden_.emplace_back(s0, s1);
  }
  std::sort(hidden_.begin(), hidden_.end());
}

// Clips the segment to the view, removes the parts hidden by triangles and emits the visible
// pieces (each at least min_length_px long).
void Visibility::emit_segment(const Segment& seg, VisibleModel& out) {
  double lo = 0, hi = 1;
  if (!clip_to_view(seg.a_cam, seg.b_cam, lo, hi)) return;
  const Eigen::Vector3d& A = seg.a_cam;
  const Eigen::Vector3d D = seg.b_cam - A;
  const Eigen::Vector3d P0 = A + lo * D, P1 = A + hi * D;
  const Eigen::Vector2d n0 = normalized(P0), n1 = normalized(P1);
  find_hidden(seg, lo, hi, n0, n1);

  // A 3D segment projects to a straight one in normalised coordinates: its clipped ends give
  // the direction the side is measured against.
  const ObjectSide side = seg.side_from_probe ? side_of(n0, n1, normalized(seg.side_probe_cam)) : ObjectSide::Both;

  auto push_piece = [&](double s0, double s1) {
    const Eigen::Vector3d a_cam = A + s0 * D, b_cam = A + s1 * D;
    const Eigen::Vector2d a_px = camera_.project(a_cam), b_px = camera_.project(b_cam);
    if ((b_px - a_px).norm() < options_.min_length_px) return;
    VisibleEdge e;
    e.edge = seg.index;
    e.kind = seg.kind;
    e.side = side;
    e.a_obj = seg.a_obj + s0 * (seg.b_obj - seg.a_obj);
    e.b_obj = seg.a_obj + s1 * (seg.b_obj - seg.a_obj);
    e.a_cam = a_cam;
    e.b_cam = b_cam;
    e.a_px = a_px;
    e.b_px = b_px;
    e.s0 = s0;
    e.s1 = s1;
    out.edges.push_back(e);
  };
  double cursor = lo;
  for (const auto& [h0, h1] : hidden_) {
    if (h0 > cursor) push_piece(cursor, std::min(h0, hi));
    cursor = std::max(cursor, h1);
    if (cursor >= hi) break;
  }
  if (cursor < hi) push_piece(cursor, hi);
}

// The model's edges: contours, creases, boundaries and wires, each with its object side probed
// by a point just inside the face the object is on.
void Visibility::add_edges(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, VisibleModel& out) {
  const CadModel& model = *model_;
  const double cos_crease = std::cos(options_.crease_angle_rad);
  for (int e = 0; e < static_cast<int>(model.edges.size()); ++e) {
    const ModelEdge& edge = model.edges[e];
    EdgeKind kind;
    int side_face = -1;  // the face whose side the object is on; -1 for Both
    if (!classify_edge(model, edge, face_front_, face_seen_, cos_crease, kind, side_face)) continue;
    const Eigen::Vector3d& A_obj = model.vertices[edge.v0];
    const Eigen::Vector3d& B_obj = model.vertices[edge.v1];
    Eigen::Vector3d probe = Eigen::Vector3d::Zero();
    if (side_face >= 0) {
      // A point just inside the face, beside the middle of the edge.
      const double len = (B_obj - A_obj).norm();
      probe = R * (0.5 * (A_obj + B_obj) + 1e-2 * len * edge.into_face[side_face]) + t;
      if (probe.z() <= options_.near_m) side_face = -1;
    }
    emit_segment({vertices_cam_[edge.v0], vertices_cam_[edge.v1], A_obj, B_obj, edge.faces[0], edge.faces[1], e, kind,
                  probe, side_face >= 0},
                 out);
  }
}

// Cylinder limbs: the two generators whose tangent planes pass through the optical centre.
void Visibility::add_limbs(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector3d& camera_obj,
                           VisibleModel& out) {
  for (int c = 0; c < static_cast<int>(model_->cylinders.size()); ++c) {
    const ModelCylinder& cyl = model_->cylinders[c];
    const Eigen::Vector3d a_obj = cyl.axis_a_obj, b_obj = cyl.axis_b_obj;
    const Eigen::Vector3d axis_obj = (b_obj - a_obj).normalized();
    Eigen::Vector3d w = camera_obj - a_obj;
    w -= w.dot(axis_obj) * axis_obj;  // from the axis to the camera, normal to the axis
    const double dist = w.norm();
    if (dist <= cyl.radius_m * (1 + 1e-9)) continue;  // camera inside the cylinder
    const Eigen::Vector3d u = w / dist;
    const Eigen::Vector3d v = axis_obj.cross(u);
    const double cos_phi = cyl.radius_m / dist;
    const double sin_phi = std::sqrt(std::max(0.0, 1 - cos_phi * cos_phi));
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d offset = cyl.radius_m * (cos_phi * u + sign * sin_phi * v);
      const Eigen::Vector3d p_obj = a_obj + offset, q_obj = b_obj + offset;
      const Eigen::Vector3d probe = R * (0.5 * (a_obj + b_obj)) + t;  // the axis is on the object side
      emit_segment({R * p_obj + t, R * q_obj + t, p_obj, q_obj, -1, -1, c, EdgeKind::CylinderSilhouette, probe,
                    probe.z() > options_.near_m},
                   out);
    }
  }
}

// Circles: the image of the circle c + r (u cos th + v sin th) is the conic
// C = H^-T diag(1, 1, -1) H^-1 with H = K [r u, r v, c]; inside is negative.
void Visibility::add_circles(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, VisibleModel& out) {
  const Eigen::Matrix3d K = camera_.K();
  for (int i = 0; i < static_cast<int>(model_->circles.size()); ++i) {
    const ModelCircle& circle = model_->circles[i];
    const Eigen::Vector3d c = R * circle.centre_obj + t;
    const Eigen::Vector3d n = (R * circle.normal_obj).normalized();
    // The lowest depth on the circle: c_z - r * |z axis projected on the plane|.
    const double zmin = c.z() - circle.radius_m * std::sqrt(std::max(0.0, 1 - n.z() * n.z()));
    if (zmin <= options_.near_m) continue;
    if (std::abs(n.dot(c)) < 1e-9 * c.norm()) continue;  // seen edge-on: degenerate
    Eigen::Vector3d u = n.unitOrthogonal();
    Eigen::Vector3d v = n.cross(u);
    Eigen::Matrix3d H;
    H.col(0) = circle.radius_m * u;
    H.col(1) = circle.radius_m * v;
    H.col(2) = c;
    H = K * H;
    const Eigen::Matrix3d Hinv = H.inverse();
    Eigen::Matrix3d C = Hinv.transpose() * Eigen::Vector3d(1, 1, -1).asDiagonal() * Hinv;
    C = 0.5 * (C + C.transpose());
    C /= C.norm();
    const Eigen::Matrix2d M = C.topLeftCorner<2, 2>();
    const Eigen::Vector2d centre = -M.ldlt().solve(C.topRightCorner<2, 1>());
    const double f_centre = C(2, 2) + C.topRightCorner<2, 1>().dot(centre);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(M);
    const Eigen::Vector2d lambda = eig.eigenvalues();  // ascending
    if (lambda[0] * lambda[1] <= 0 || -f_centre / lambda[0] <= 0) continue;  // not an ellipse
    VisibleEllipse ellipse;
    ellipse.circle = i;
    ellipse.conic_px = C;
    ellipse.centre_px = centre;
    ellipse.semi_major_px = std::sqrt(-f_centre / lambda[0]);
    ellipse.semi_minor_px = std::sqrt(-f_centre / lambda[1]);
    const Eigen::Vector2d major = eig.eigenvectors().col(0);
    ellipse.angle_rad = std::atan2(major.y(), major.x());
    ellipse.facing_camera = n.dot(-c) > 0;
    const double r = ellipse.semi_major_px;
    if (centre.x() + r < 0 || centre.x() - r > camera_.width_px() || centre.y() + r < 0 ||
        centre.y() - r > camera_.height_px())
      continue;
    if (options_.clip_circles && !seen_arc(circle, c, u, v, centre, ellipse.seen)) continue;
    out.ellipses.push_back(ellipse);
  }
}

// The circle as kChords chords, each tested at its middle against the occluders like an edge.
// No face counts as the circle's own, but a face hides a point only from further in front than
// a tenth of the radius: a rim modelled by facets runs up to the facets' sagitta inside or
// outside them, while what really hides a rim (the body in front of its far half) is a
// diameter away. The seen arc is the longest run of seen chords, from the middle of its first
// chord to the middle of its last: never onto a hidden part.
bool Visibility::seen_arc(const ModelCircle& circle, const Eigen::Vector3d& c, const Eigen::Vector3d& u,
                          const Eigen::Vector3d& v, const Eigen::Vector2d& centre_px, EllipseArc& arc) {
  constexpr int kChords = 48;
  constexpr double kStep = 2 * std::numbers::pi / kChords;
  auto at = [&](double th) -> Eigen::Vector3d { return c + circle.radius_m * (std::cos(th) * u + std::sin(th) * v); };
  std::array<unsigned char, kChords> chord_seen{};
  int seen = 0;
  for (int k = 0; k < kChords; ++k) {
    const Eigen::Vector3d A = at(k * kStep), B = at((k + 1) * kStep);
    // find_hidden reads only the camera-frame ends and the own faces (none) of a segment.
    const Segment chord{A, B, A, B, -1, -1, -1, EdgeKind::Contour, A, false};
    find_hidden(chord, 0.0, 1.0, normalized(A), normalized(B), 0.1 * circle.radius_m);
    bool hidden = false;
    for (const auto& [h0, h1] : hidden_) hidden = hidden || (h0 <= 0.5 && 0.5 <= h1);
    chord_seen[static_cast<std::size_t>(k)] = !hidden;
    seen += !hidden;
  }
  arc = EllipseArc{};
  if (seen == kChords) return true;
  if (seen == 0) return false;
  // The longest cyclic run of seen chords: it starts after a hidden one.
  int best_start = 0, best_len = 0;
  for (int s = 0; s < kChords; ++s) {
    if (!chord_seen[static_cast<std::size_t>(s)] || chord_seen[static_cast<std::size_t>((s + kChords - 1) % kChords)]) continue;
    int len = 0;
    while (len < kChords && chord_seen[static_cast<std::size_t>((s + len) % kChords)]) ++len;
    if (len > best_len) { best_start = s; best_len = len; }
  }
  const Eigen::Matrix3d K = camera_.K();
  auto polar = [&](double th) {
    const Eigen::Vector3d p = K * at(th);
    return std::atan2(p.y() / p.z() - centre_px.y(), p.x() / p.z() - centre_px.x());
  };
  auto forward = [](double from, double to) {  // angle swept from `from` to `to` growing, in [0, 2 pi)
    const double two_pi = 2 * std::numbers::pi;
    return std::fmod(std::fmod(to - from, two_pi) + two_pi, two_pi);
  };
  const double th0 = (best_start + 0.5) * kStep, th1 = (best_start + best_len - 0.5) * kStep;
  const double p0 = polar(th0), p1 = polar(th1), pm = polar(0.5 * (th0 + th1));
  // The image may run the circle either way round: the arc is the way that passes its middle.
  if (forward(p0, pm) <= forward(p0, p1)) arc = EllipseArc{p0, forward(p0, p1)};
  else arc = EllipseArc{p1, forward(p1, p0)};
  return true;
}

VisibleModel compute_visibility(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj,
                                const VisibilityOptions& options) {
  Visibility visibility(model, camera, options);
  VisibleModel out;
  visibility.compute(cam_T_obj, out);
  return out;
}

}  // namespace epichead::vision
