// Visibility against a brute-force ray caster: for points sampled along every model edge, the
// point is visible iff the ray from the optical centre to it crosses no face other than the
// edge's own. The clipped pieces that Visibility returns must agree everywhere except within
// a hair of a piece's end.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "epichead/vision/look_at.h"
#include "epichead/vision/visibility.h"

using namespace epichead::vision;

namespace {

Camera test_camera(const Distortion& dist = {}) { return Camera(640, 480, {500, 500, 320, 240}, dist); }

// cam_T_obj for a camera at `eye` (object frame) looking at `target`.
Eigen::Isometry3d camera_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  return epichead::vision::look_at(eye, target).inverse();
}

CadModel make_prism(const std::vector<Eigen::Vector2d>& profile_ccw, double height) {
  RawModel raw;
  const int n = static_cast<int>(profile_ccw.size());
  for (const auto& p : profile_ccw) raw.vertices.emplace_back(p.x(), p.y(), 0);
  for (const auto& p : profile_ccw) raw.vertices.emplace_back(p.x(), p.y(), height);
  std::vector<int> bottom, top;
  for (int i = n - 1; i >= 0; --i) bottom.push_back(i);  // seen from below (outside): reversed
  for (int i = 0; i < n; ++i) top.push_back(n + i);
  raw.face_loops.push_back(bottom);
  raw.face_loops.push_back(top);
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    raw.face_loops.push_back({i, j, n + j, n + i});
  }
  auto model = build_model(raw, "prism");
  REQUIRE(model.has_value());
  return *model;
}

// An edge of make_cube()'s x = 0.1 face.
bool on_cube_x_max_face(const VisibleEdge& e) { return e.a_obj.x() > 0.099 && e.b_obj.x() > 0.099; }

CadModel make_cube() { return make_prism({{0, 0}, {0.1, 0}, {0.1, 0.1}, {0, 0.1}}, 0.1); }

CadModel make_l_shape() {
  return make_prism({{0, 0}, {0.2, 0}, {0.2, 0.1}, {0.1, 0.1}, {0.1, 0.2}, {0, 0.2}}, 0.1);
}

// Point-in-polygon on the face plane (crossing number in the dominant projection).
bool inside_face(const CadModel& m, const ModelFace& face, const Eigen::Vector3d& x) {
  int drop = 0;
  face.normal_obj.cwiseAbs().maxCoeff(&drop);
  const int a = (drop + 1) % 3, b = (drop + 2) % 3;
  bool inside = false;
  const std::size_t n = face.vertices.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Eigen::Vector3d& pi = m.vertices[face.vertices[i]];
    const Eigen::Vector3d& pj = m.vertices[face.vertices[j]];
    if ((pi[b] > x[b]) != (pj[b] > x[b]) &&
        x[a] < (pj[a] - pi[a]) * (x[b] - pi[b]) / (pj[b] - pi[b]) + pi[a])
      inside = !inside;
  }
  return inside;
}

// True when the segment from the camera centre to p_obj crosses a face other than skip_a/skip_b
// strictly before p_obj.
bool ray_blocked(const CadModel& m, const Eigen::Vector3d& camera_obj, const Eigen::Vector3d& p_obj, int skip_a,
                 int skip_b) {
  const Eigen::Vector3d d = p_obj - camera_obj;
  for (int f = 0; f < static_cast<int>(m.faces.size()); ++f) {
    if (f == skip_a || f == skip_b) continue;
    const ModelFace& face = m.faces[f];
    const double denom = face.normal_obj.dot(d);
    if (std::abs(denom) < 1e-12) continue;
    const double lambda = (face.offset_m - face.normal_obj.dot(camera_obj)) / denom;
    if (lambda <= 1e-9 || lambda >= 1 - 1e-6) continue;
    if (inside_face(m, face, camera_obj + lambda * d)) return true;
  }
  return false;
}

// Compares Visibility with the ray caster on one pose. Returns the number of partly hidden edges.
int check_against_ray_caster(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj) {
  VisibleModel out = compute_visibility(model, camera, cam_T_obj);
  const Eigen::Vector3d camera_obj = cam_T_obj.inverse().translation();
  int partly_hidden = 0;
  for (int e = 0; e < static_cast<int>(model.edges.size()); ++e) {
    const ModelEdge& edge = model.edges[e];
    std::vector<std::pair<double, double>> pieces;
    for (const auto& v : out.edges)
      if (v.edge == e) pieces.emplace_back(v.s0, v.s1);
    if (!pieces.empty() && (pieces.front().first > 1e-6 || pieces.back().second < 1 - 1e-6)) ++partly_hidden;
    const Eigen::Vector3d A = model.vertices[edge.v0], B = model.vertices[edge.v1];
    constexpr int kSamples = 400;
    for (int k = 1; k < kSamples; ++k) {
      const double s = static_cast<double>(k) / kSamples;
      bool near_end = false, in_piece = false;
      for (const auto& [s0, s1] : pieces) {
        if (std::abs(s - s0) < 4e-3 || std::abs(s - s1) < 4e-3) near_end = true;
        if (s > s0 && s < s1) in_piece = true;
      }
      if (near_end) continue;
      const bool visible = !ray_blocked(model, camera_obj, A + s * (B - A), edge.faces[0], edge.faces[1]);
      // The ray caster sees an unblocked point on an edge between two back faces of a closed
      // solid only at grazing angles; those edges are culled by rule, so skip ambiguous ones.
      INFO("edge " << e << " s " << s);
      if (visible != in_piece) {
        // Allow a miss only where the raw ray test itself is marginal (grazing the blocker's border).
        const double eps = 2e-3;
        const bool marginal =
            ray_blocked(model, camera_obj, A + std::min(1.0, s + eps) * (B - A), edge.faces[0], edge.faces[1]) != visible ||
            ray_blocked(model, camera_obj, A + std::max(0.0, s - eps) * (B - A), edge.faces[0], edge.faces[1]) != visible;
        CHECK(marginal);
      }
    }
  }
  return partly_hidden;
}

// A pixel's ray hits the model (any face).
bool pixel_on_object(const CadModel& m, const Camera& camera, const Eigen::Isometry3d& cam_T_obj,
                     const Eigen::Vector2d& px) {
  const Eigen::Isometry3d obj_T_cam = cam_T_obj.inverse();
  const Eigen::Vector3d origin = obj_T_cam.translation();
  const Eigen::Vector3d far_point = obj_T_cam * (camera.unproject(px) * 100.0);
  return ray_blocked(m, origin, far_point, -1, -1);
}

}  // namespace

TEST_CASE("cube seen from a corner shows six contour and three crease edges", "[visibility]") {
  const CadModel cube = make_cube();
  const Camera camera = test_camera();
  const auto pose = camera_at({0.5, 0.4, 0.45}, {0.05, 0.05, 0.05});
  const VisibleModel out = compute_visibility(cube, camera, pose);
  int contour = 0, crease = 0;
  for (const auto& e : out.edges) {
    CHECK(e.s0 == Approx(0).margin(1e-9));
    CHECK(e.s1 == Approx(1).margin(1e-9));
    contour += e.kind == EdgeKind::Contour;
    crease += e.kind == EdgeKind::Crease;
  }
  CHECK(out.edges.size() == 9);
  CHECK(contour == 6);
  CHECK(crease == 3);
}

TEST_CASE("object side of every contour edge is where the object is in the image", "[visibility]") {
  const CadModel cube = make_cube();
  const Camera camera = test_camera();
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), elev(-1.2, 1.2);
  for (int trial = 0; trial < 40; ++trial) {
    const double az = angle(rng), el = elev(rng);
    const Eigen::Vector3d eye = Eigen::Vector3d(0.05, 0.05, 0.05) +
                                0.5 * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const auto pose = camera_at(eye, {0.05, 0.05, 0.05});
    // Geometric truth: every front face counts (the default hands a face seen nearly edge-on
    // to the background side on purpose, see the next test); on views with no face within
    // 84-90 deg the default must agree as well.
    VisibilityOptions all_front;
    all_front.max_view_angle_rad = M_PI / 2;
    double steepest_graze = 0;  // the largest view angle of a front face, deg (at any vertex)
    for (const auto& f : cube.faces)
      for (int v : f.vertices) {
        const Eigen::Vector3d to_eye = eye - cube.vertices[static_cast<std::size_t>(v)];
        const double c = f.normal_obj.dot(to_eye) / to_eye.norm();
        if (c > 0) steepest_graze = std::max(steepest_graze, std::acos(c) * 180 / M_PI);
      }
    const bool default_too = steepest_graze < 84;
    for (int run = 0; run < (default_too ? 2 : 1); ++run) {
      const VisibilityOptions options = run == 0 ? all_front : VisibilityOptions{};
      for (const auto& e : compute_visibility(cube, camera, pose, options).edges) {
        const Eigen::Vector2d mid = 0.5 * (e.a_px + e.b_px);
        const Eigen::Vector2d d = (e.b_px - e.a_px).normalized();
        const Eigen::Vector2d left(d.y(), -d.x());
        // Just beside the edge: a face seen nearly edge-on may be under a pixel wide.
        const bool on_left = pixel_on_object(cube, camera, pose, mid + 0.25 * left);
        const bool on_right = pixel_on_object(cube, camera, pose, mid - 0.25 * left);
        INFO("trial " << trial << " edge " << e.edge);
        switch (e.side) {
          case ObjectSide::Left: CHECK(on_left); CHECK_FALSE(on_right); break;
          case ObjectSide::Right: CHECK(on_right); CHECK_FALSE(on_left); break;
          case ObjectSide::Both: CHECK(on_left); CHECK(on_right); CHECK(e.kind == EdgeKind::Crease); break;
        }
      }
    }
  }
}

TEST_CASE("visible pieces agree with a ray caster on the cube and the non-convex L-shape", "[visibility]") {
  const Camera camera = test_camera();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(0, 2 * M_PI), elev(-1.3, 1.3), dist(0.45, 0.9);
  for (const auto& [name, model] : {std::pair{"cube", make_cube()}, std::pair{"l_shape", make_l_shape()}}) {
    int partly_hidden = 0;
    for (int trial = 0; trial < 60; ++trial) {
      const double az = angle(rng), el = elev(rng);
      const Eigen::Vector3d centre(0.08, 0.08, 0.05);
      const Eigen::Vector3d eye =
          centre + dist(rng) * Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      INFO(name << " trial " << trial);
      partly_hidden += check_against_ray_caster(model, camera, camera_at(eye, centre));
    }
    // The L-shape's arms hide parts of each other's edges from many directions; the cube never does.
    if (std::string(name) == "l_shape") CHECK(partly_hidden > 10);
    else CHECK(partly_hidden == 0);
  }
}

TEST_CASE("an L-shape edge behind the other arm is clipped to its visible pieces, not dropped", "[visibility]") {
  const CadModel l = make_l_shape();
  const Camera camera = test_camera();
  // From the upper left, below the top, the upper arm (x 0..0.1, y 0.1..0.2) stands in front of
  // the lower arm's face y = 0.1 and hides the near part (x < ~0.157) of its top edge
  // (0.1, 0.1, 0.1)-(0.2, 0.1, 0.1); the rest stays visible.
  const auto pose = camera_at({-0.3, 0.9, 0.05}, {0.15, 0.05, 0.05});
  const VisibleModel out = compute_visibility(l, camera, pose);
  int far_edge = -1;
  for (int e = 0; e < static_cast<int>(l.edges.size()); ++e) {
    const auto a = l.vertices[l.edges[e].v0], b = l.vertices[l.edges[e].v1];
    const auto on_edge = [](const Eigen::Vector3d& p) {
      return std::abs(p.y() - 0.1) < 1e-9 && std::abs(p.z() - 0.1) < 1e-9 && p.x() > 0.05;
    };
    if (on_edge(a) && on_edge(b)) far_edge = e;
  }
  REQUIRE(far_edge >= 0);
  double visible_fraction = 0;
  int pieces = 0;
  for (const auto& e : out.edges)
    if (e.edge == far_edge) { visible_fraction += e.s1 - e.s0; ++pieces; }
  CHECK(pieces >= 1);
  CHECK(visible_fraction == Approx(0.43).margin(0.03));
  check_against_ray_caster(l, camera, pose);
}

TEST_CASE("a face seen nearly edge-on gives up its far edge, and its near edge becomes a contour", "[visibility]") {
  // The camera faces the cube's y = 0 face and sees its x = 0.1 face at about 88 deg.
  const CadModel cube = make_cube();
  const Camera camera = test_camera();
  const auto pose = camera_at({0.12, -0.5, 0.35}, {0.05, 0.05, 0.05});
  auto far_vertical = [&](const VisibleEdge& e) { return on_cube_x_max_face(e) && e.a_obj.y() > 0.099 && e.b_obj.y() > 0.099; };

  VisibilityOptions all_front;
  all_front.max_view_angle_rad = M_PI / 2;
  const VisibleModel strict = compute_visibility(cube, camera, pose, all_front);
  int far = 0, right_creases = 0, right_strict = 0;
  for (const auto& e : strict.edges) {
    far += far_vertical(e);
    right_strict += on_cube_x_max_face(e);
    right_creases += on_cube_x_max_face(e) && e.kind == EdgeKind::Crease;
  }
  CHECK(right_strict == 4);   // 90 deg: all four edges of the sliver: its far vertical and
  CHECK(far == 1);            // bottom edges (contours) ...
  CHECK(right_creases == 2);  // ... and its near edges (creases with the front and top faces)

  const VisibleModel out = compute_visibility(cube, camera, pose);  // default 85 deg
  int right = 0;
  for (const auto& e : out.edges) {
    CHECK_FALSE(far_vertical(e));
    if (!on_cube_x_max_face(e)) continue;
    ++right;
    CHECK(e.kind == EdgeKind::Contour);
    CHECK(e.side != ObjectSide::Both);
  }
  CHECK(right == 2);  // the front and top edges of the sliver
  CHECK(out.edges.size() + 2 == strict.edges.size());
}

TEST_CASE("a face near the view-angle limit is decided once: all its edges agree", "[visibility]") {
  // Sweep the camera so that the cube's x = 0.1 face passes through 85 deg: at every step either
  // its far edges are gone and its near edges are contours, or all four edges are there with its
  // near edges creases; never a mix (a side with no contour at all).
  const CadModel cube = make_cube();
  const Camera camera = test_camera();
  int turned_away = 0, seen = 0;
  for (double cx = 0.13; cx <= 0.19; cx += 0.0025) {
    const auto pose = camera_at({cx, -0.5, 0.35}, {0.05, 0.05, 0.05});
    int right = 0, contours = 0, creases = 0;
    for (const auto& e : compute_visibility(cube, camera, pose).edges) {
      if (!on_cube_x_max_face(e)) continue;
      ++right;
      contours += e.kind == EdgeKind::Contour;
      creases += e.kind == EdgeKind::Crease;
    }
    INFO("camera x " << cx);
    if (right == 2) {
      CHECK(contours == 2);
      ++turned_away;
    } else {
      CHECK(right == 4);
      CHECK(creases == 2);
      ++seen;
    }
  }
  CHECK(turned_away > 0);  // the sweep crosses the limit
  CHECK(seen > 0);
}

TEST_CASE("edges between nearly coplanar facets are dropped unless on the silhouette", "[visibility]") {
  // A 36-sided prism approximates a cylinder: facets differ by 10 degrees, under the default
  // crease angle of 20 degrees.
  std::vector<Eigen::Vector2d> profile;
  for (int i = 0; i < 36; ++i) profile.emplace_back(0.1 * std::cos(i * M_PI / 18), 0.1 * std::sin(i * M_PI / 18));
  const CadModel prism = make_prism(profile, 0.3);
  const Camera camera = test_camera();
  const auto pose = camera_at({1.2, 0.3, 0.15}, {0, 0, 0.15});
  const VisibleModel out = compute_visibility(prism, camera, pose);
  int vertical_contours = 0, vertical_creases = 0;
  for (const auto& e : out.edges) {
    const bool vertical = std::abs(e.a_obj.z() - e.b_obj.z()) > 0.2;
    if (!vertical) continue;
    vertical_contours += e.kind == EdgeKind::Contour;
    vertical_creases += e.kind == EdgeKind::Crease;
  }
  CHECK(vertical_contours == 2);  // the two limbs
  CHECK(vertical_creases == 0);
  // With a crease angle under the facet angle, the facet edges come back.
  VisibilityOptions fine;
  fine.crease_angle_rad = 5 * M_PI / 180;
  int creases = 0;
  for (const auto& e : compute_visibility(prism, camera, pose, fine).edges)
    creases += e.kind == EdgeKind::Crease && std::abs(e.a_obj.z() - e.b_obj.z()) > 0.2;
  CHECK(creases > 5);
}

TEST_CASE("a model behind the camera is invisible and one crossing the near plane is clipped", "[visibility]") {
  const CadModel cube = make_cube();
  const Camera camera = test_camera();
  Eigen::Isometry3d behind = Eigen::Isometry3d::Identity();
  behind.translation() = Eigen::Vector3d(-0.05, -0.05, -0.5);
  CHECK(compute_visibility(cube, camera, behind).edges.empty());

  Eigen::Isometry3d straddle = Eigen::Isometry3d::Identity();
  straddle.translation() = Eigen::Vector3d(-0.05, -0.05, -0.05);  // z from -0.05 to 0.05
  VisibilityOptions opt;
  opt.near_m = 0.01;
  for (const auto& e : compute_visibility(cube, camera, straddle, opt).edges) {
    CHECK(e.a_cam.z() >= 0.01 - 1e-12);
    CHECK(e.b_cam.z() >= 0.01 - 1e-12);
  }
}

TEST_CASE("visible pieces are clipped to the image, also with lens distortion", "[visibility]") {
  const CadModel cube = make_cube();
  for (const Distortion& dist : {Distortion{}, Distortion{-0.3, 0.1, 0.001, -0.001, 0}}) {
    const Camera camera = test_camera(dist);
    const auto pose = camera_at({0.2, 0.12, 0.14}, {0.05, 0.05, 0.05});  // close: the cube overflows the image
    const VisibleModel out = compute_visibility(cube, camera, pose);
    CHECK_FALSE(out.edges.empty());
    for (const auto& e : out.edges) {
      CHECK(camera.in_image(e.a_px, -0.5));
      CHECK(camera.in_image(e.b_px, -0.5));
    }
  }
}

TEST_CASE("a projected circle is the ellipse through its projected points", "[visibility]") {
  CadModel model;
  ModelCircle circle;
  circle.centre_obj = {0.02, -0.01, 0.0};
  circle.normal_obj = Eigen::Vector3d(0.2, 0.3, 1).normalized();
  circle.radius_m = 0.08;
  model.circles.push_back(circle);
  const Camera camera = test_camera();
  const auto pose = camera_at({0.3, -0.4, 0.5}, {0, 0, 0});
  const VisibleModel out = compute_visibility(model, camera, pose);
  REQUIRE(out.ellipses.size() == 1);
  const VisibleEllipse& el = out.ellipses[0];
  const Eigen::Vector3d u = circle.normal_obj.unitOrthogonal(), v = circle.normal_obj.cross(u);
  const double ca = std::cos(el.angle_rad), sa = std::sin(el.angle_rad);
  for (int k = 0; k < 72; ++k) {
    const double th = k * M_PI / 36;
    const Eigen::Vector3d p = circle.centre_obj + circle.radius_m * (std::cos(th) * u + std::sin(th) * v);
    const Eigen::Vector2d px = camera.project(pose * p);
    // On the conic, and on the ellipse given by centre, axes and angle.
    const Eigen::Vector3d h(px.x(), px.y(), 1);
    const Eigen::Vector3d grad = 2 * el.conic_px * h;
    CHECK(std::abs(h.dot(el.conic_px * h)) / grad.head<2>().norm() < 1e-6);  // algebraic -> ~pixel distance
    const Eigen::Vector2d q = px - el.centre_px;
    const double x = ca * q.x() + sa * q.y(), y = -sa * q.x() + ca * q.y();
    CHECK(x * x / (el.semi_major_px * el.semi_major_px) + y * y / (el.semi_minor_px * el.semi_minor_px) ==
          Approx(1).epsilon(1e-6));
  }
  CHECK(el.semi_major_px >= el.semi_minor_px);
  CHECK(el.facing_camera);
}

TEST_CASE("cylinder limbs are tangent: the whole surface lies on the axis side of each", "[visibility]") {
  CadModel model;
  model.cylinders.push_back({{0, 0, 0}, {0, 0, 0.3}, 0.05});
  const Camera camera = test_camera();
  const auto pose = camera_at({0.6, 0.4, 0.4}, {0, 0, 0.15});
  const VisibleModel out = compute_visibility(model, camera, pose);
  REQUIRE(out.edges.size() == 2);
  for (const auto& e : out.edges) {
    CHECK(e.kind == EdgeKind::CylinderSilhouette);
    REQUIRE(e.side != ObjectSide::Both);
    const Eigen::Vector2d d = (e.b_px - e.a_px).normalized();
    const Eigen::Vector2d left(d.y(), -d.x());
    const double sign = e.side == ObjectSide::Left ? 1 : -1;
    double min_offset = 1e9;
    for (int i = 0; i <= 20; ++i)
      for (int k = 0; k < 180; ++k) {
        const double th = k * M_PI / 90;
        const Eigen::Vector3d p(0.05 * std::cos(th), 0.05 * std::sin(th), 0.3 * i / 20);
        const Eigen::Vector2d px = camera.project(pose * p);
        min_offset = std::min(min_offset, sign * (px - e.a_px).dot(left));
      }
    CHECK(min_offset > -0.05);  // within rounding of the tangent line
    CHECK(min_offset < 0.05);   // and touching it
  }
}

namespace {

// Whether polar angle `a` lies on `arc` (within `slack_rad` of it).
bool on_arc(const EllipseArc& arc, double a, double slack_rad) {
  const double d = std::fmod(std::fmod(a - arc.begin_rad + slack_rad, 2 * M_PI) + 2 * M_PI, 2 * M_PI);
  return d <= arc.span_rad + 2 * slack_rad;
}

}  // namespace

TEST_CASE("a can's bottom rim seen from above is seen only on its near half, its top rim all round", "[visibility]") {
  // 32 facets with their corners on the rims, as CAO users model a can.
  std::vector<Eigen::Vector2d> profile;
  for (int i = 0; i < 32; ++i) profile.emplace_back(0.04 * std::cos(i * M_PI / 16), 0.04 * std::sin(i * M_PI / 16));
  CadModel model = make_prism(profile, 0.1);
  for (const double z : {0.0, 0.1}) {
    ModelCircle rim;
    rim.centre_obj = {0, 0, z};
    rim.normal_obj = Eigen::Vector3d::UnitZ();
    rim.radius_m = 0.04;
    model.circles.push_back(rim);
  }
  const Camera camera = test_camera();
  const Eigen::Vector3d eye(0.05, -0.45, 0.25);  // in front of the can and above it
  const auto pose = camera_at(eye, {0, 0, 0.05});
  const VisibleModel out = compute_visibility(model, camera, pose);
  REQUIRE(out.ellipses.size() == 2);
  for (const VisibleEllipse& el : out.ellipses) {
    const bool bottom = model.circles[static_cast<std::size_t>(el.circle)].centre_obj.z() < 0.05;
    INFO((bottom ? "bottom rim" : "top rim") << ": seen from " << el.seen.begin_rad << " over " << el.seen.span_rad);
    if (!bottom) {
      CHECK(el.seen.full());
      continue;
    }
    CHECK(el.seen.span_rad > 0.8 * M_PI);
    CHECK(el.seen.span_rad < 1.3 * M_PI);
    // Rim points turned toward the camera are on the seen arc, those turned away are not.
    const Eigen::Vector2d toward = Eigen::Vector2d(eye.x(), eye.y()).normalized();
    for (int k = 0; k < 72; ++k) {
      const double th = k * M_PI / 36;
      const Eigen::Vector2d radial(std::cos(th), std::sin(th));
      const Eigen::Vector2d px = camera.project(pose * Eigen::Vector3d(0.04 * radial.x(), 0.04 * radial.y(), 0));
      const double polar = std::atan2(px.y() - el.centre_px.y(), px.x() - el.centre_px.x());
      const double facing = radial.dot(toward);
      INFO("rim point at " << th << " rad, facing " << facing);
      if (facing > 0.3) CHECK(on_arc(el.seen, polar, 0.0));
      if (facing < -0.3) CHECK_FALSE(on_arc(el.seen, polar, 0.0));
    }
  }
}

TEST_CASE("a rim hidden all round by its own body is left out", "[visibility]") {
  // A disc inside a box: the circle lies in the middle of the box, never seen.
  CadModel model = make_cube();
  ModelCircle inner;
  inner.centre_obj = {0.05, 0.05, 0.05};
  inner.normal_obj = Eigen::Vector3d::UnitZ();
  inner.radius_m = 0.02;
  model.circles.push_back(inner);
  const VisibleModel out = compute_visibility(model, test_camera(), camera_at({0.3, -0.4, 0.5}, {0.05, 0.05, 0.05}));
  CHECK(out.ellipses.empty());
}
