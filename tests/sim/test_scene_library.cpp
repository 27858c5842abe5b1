// The built-in scenes: each builds, its model file round-trips through the CAO reader and
// matches the model built in code, it has the features its scenario needs, and the suggested
// viewpoint sees it.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/sim/renderer.h"
#include "epichead/sim/scene_library.h"
#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/visibility.h"

using namespace epichead;

namespace {

vision::Camera default_camera() { return vision::Camera(640, 480, {839.2, 839.4, 325.7, 243.7}); }

// Distinct model edges seen from the scene's suggested viewpoint.
int visible_edges(const sim::Scene& s) {
  const Eigen::Isometry3d cam_T_obj = sim::look_at(s.view.camera_world, s.view.target_world).inverse() * s.world_T_obj;
  const vision::VisibleModel vis = vision::compute_visibility(s.model, default_camera(), cam_T_obj);
  std::set<int> edges;
  for (const auto& e : vis.edges)
    if (e.kind != vision::EdgeKind::CylinderSilhouette) edges.insert(e.edge);
  return static_cast<int>(edges.size());
}

Eigen::Vector3d direction(const vision::CadModel& m, const vision::ModelEdge& e) {
  return (m.vertices[static_cast<std::size_t>(e.v1)] - m.vertices[static_cast<std::size_t>(e.v0)]).normalized();
}

}  // namespace

TEST_CASE("every built-in scene builds and its model file matches the model built in code", "[scene_library]") {
  REQUIRE(sim::scene_names().size() == 6);
  for (const auto& name : sim::scene_names()) {
    CAPTURE(name);
    auto scene = sim::make_scene(name);
    REQUIRE(scene);
    CHECK(scene->name == name);
    CHECK(scene->world_T_obj.isApprox(Eigen::Isometry3d::Identity()));
    CHECK(scene->model.warnings.empty());
    // The committed CAO file as built into the program (what a sequence's model.cao is).
    const auto cao = sim::scene_model_cao(name);
    REQUIRE(cao);
    auto from_file = vision::parse_cao(std::string(*cao), name + ".cao");
    REQUIRE(from_file);
    const vision::CadModel& a = scene->model;
    const vision::CadModel& b = *from_file;
    REQUIRE(a.faces.size() == b.faces.size());
    REQUIRE(a.circles.size() == b.circles.size());
    CHECK(a.edges.size() == b.edges.size());
    CHECK(a.closed == b.closed);
    for (std::size_t f = 0; f < a.faces.size(); ++f) {
      REQUIRE(a.faces[f].vertices.size() == b.faces[f].vertices.size());
      for (std::size_t k = 0; k < a.faces[f].vertices.size(); ++k)
        CHECK((a.vertices[static_cast<std::size_t>(a.faces[f].vertices[k])] -
               b.vertices[static_cast<std::size_t>(b.faces[f].vertices[k])]).norm() < 1e-12);
      CHECK(a.faces[f].normal_obj.dot(b.faces[f].normal_obj) > 1 - 1e-12);
    }
    for (std::size_t c = 0; c < a.circles.size(); ++c) {
      CHECK((a.circles[c].centre_obj - b.circles[c].centre_obj).norm() < 1e-12);
      CHECK(a.circles[c].normal_obj.dot(b.circles[c].normal_obj) > 1 - 1e-12);
      CHECK(a.circles[c].radius_m == Approx(b.circles[c].radius_m));
    }
    // And the writer round-trips it too.
    auto reparsed = vision::parse_cao(vision::to_cao(a), name);
    REQUIRE(reparsed);
    CHECK(reparsed->faces.size() == a.faces.size());
  }
}

TEST_CASE("every built-in scene is in view from its suggested viewpoint and renders a textured frame", "[scene_library]") {
  const vision::Camera cam = default_camera();
  for (const auto& name : sim::scene_names()) {
    CAPTURE(name);
    auto scene = sim::make_scene(name);
    REQUIRE(scene);
    const auto& v = scene->view;
    CHECK(v.distance_m == Approx((v.camera_world - v.target_world).norm()));
    CHECK(v.distance_m >= v.min_distance_m);
    CHECK(v.distance_m <= v.max_distance_m);
    const Eigen::Isometry3d world_T_cam = sim::look_at(v.camera_world, v.target_world);
    // Most model vertices project into the image.
    int inside = 0;
    for (const auto& p : scene->model.vertices) {
      const Eigen::Vector3d pc = world_T_cam.inverse() * (scene->world_T_obj * p);
      inside += pc.z() > 0 && cam.in_image(cam.project(pc));
    }
    CHECK(inside >= static_cast<int>(scene->model.vertices.size()) / 2);
    // At least two faces' worth of edges (a box seen on two faces shows 7; a third face seen
    // nearly edge-on counts as turned away, VisibilityOptions::max_view_angle_rad).
    CHECK(visible_edges(*scene) >= 7);
    sim::RenderOptions o;
    o.samples_per_subframe = 2;
    sim::Renderer r(*scene, cam, o);
    std::vector<sim::SubFrame> subs(1);
    subs[0].world_T_cam = world_T_cam;
    sim::FrameInput f;
    f.sub_frames = subs;
    cv::RNG rng(1);
    const cv::Mat img = r.render(f, rng);
    cv::Scalar mean, dev;
    cv::meanStdDev(img, mean, dev);
    CHECK(dev[1] > 15);  // structure, not a flat colour
    CHECK(mean[1] > 40);
    CHECK(mean[1] < 220);
  }
}

TEST_CASE("mockup_walk: low-contrast plates, a T-truss, three parallel stiffener edges 3 cm apart, 25+ visible lines", "[scene_library]") {
  auto scene = sim::make_scene("mockup_walk");
  REQUIRE(scene);
  const vision::CadModel& m = scene->model;
  CHECK(m.closed);
  // The top front edges of the three flat bars: parallel to x at z = 0.06, consecutive ones
  // within 5 cm of each other and all within 7 cm.
  std::vector<double> ys;
  for (const auto& e : m.edges) {
    const Eigen::Vector3d& a = m.vertices[static_cast<std::size_t>(e.v0)];
    const Eigen::Vector3d& b = m.vertices[static_cast<std::size_t>(e.v1)];
    if (std::abs(direction(m, e).x()) > 0.999 && std::abs(a.z() - 0.06) < 1e-9 && std::abs(b.z() - 0.06) < 1e-9 &&
        a.y() < -0.15)
      ys.push_back(a.y());
  }
  std::sort(ys.begin(), ys.end());
  ys.erase(std::unique(ys.begin(), ys.end(), [](double p, double q) { return std::abs(p - q) < 0.015; }), ys.end());
  REQUIRE(ys.size() == 3);
  CHECK(ys[1] - ys[0] <= 0.05);
  CHECK(ys[2] - ys[1] <= 0.05);
  // They are parallel pairs of the model topology, too.
  int close_pairs = 0;
  for (const auto& p : m.parallel_pairs) close_pairs += p.distance_m > 0.02 && p.distance_m <= 0.05;
  CHECK(close_pairs >= 2);
  // Plates of one colour: reflectances within 0.55 .. 0.62.
  for (const auto& mat : scene->materials) {
    CHECK(mat.albedo_bgr.minCoeff() >= 0.55f - 1e-6f);
    CHECK(mat.albedo_bgr.maxCoeff() <= 0.62f + 1e-6f);
  }
  CHECK(visible_edges(*scene) >= 25);
}

// Facets of a body of revolution: every pair of neighbouring faces is below the crease angle
// (their shared edge makes no image edge and is not tracked).
void check_facets_below_crease(const vision::CadModel& m) {
  const double crease = vision::VisibilityOptions{}.crease_angle_rad;
  for (const auto& e : m.edges) {
    if (e.face_count() != 2) continue;
    const double angle = std::acos(std::clamp(m.faces[static_cast<std::size_t>(e.faces[0])].normal_obj.dot(
                                                  m.faces[static_cast<std::size_t>(e.faces[1])].normal_obj),
                                              -1.0, 1.0));
    CHECK(angle < crease);
  }
}

TEST_CASE("lampshade: two rim circles, facets below the crease angle, an open surface and an arm occluder", "[scene_library]") {
  auto scene = sim::make_scene("lampshade");
  REQUIRE(scene);
  const vision::CadModel& m = scene->model;
  REQUIRE(m.circles.size() == 2);
  CHECK(m.circles[0].radius_m > m.circles[1].radius_m);
  CHECK(std::abs(m.circles[1].centre_obj.z() - m.circles[0].centre_obj.z()) > 0.1);
  CHECK_FALSE(m.closed);
  CHECK(m.faces.size() >= 24);
  check_facets_below_crease(m);
  REQUIRE(scene->occluders.size() == 1);
  REQUIRE(scene->occluder_paths.size() == 1);
  // The arm's default path crosses the line of sight to the shade.
  const Eigen::Vector3d a = sim::occluder_pose(scene->occluder_paths[0], 0.0).translation();
  const Eigen::Vector3d b = sim::occluder_pose(scene->occluder_paths[0], scene->occluder_paths[0].start_s +
                                                                              scene->occluder_paths[0].period_s / 2)
                                .translation();
  CHECK(a.x() * b.x() < 0);
  // Reflectance varies along the rim and over time.
  bool varies = false;
  for (const auto& mat : scene->materials)
    varies = varies || (mat.gradient_per_m_obj.norm() > 0 && mat.gradient_swing > 0 && mat.change_amplitude > 0);
  CHECK(varies);
}

TEST_CASE("can: 32 facets and two rim circles, 4 cm radius, 12 cm high, a smooth printed render", "[scene_library]") {
  auto scene = sim::make_scene("can");
  REQUIRE(scene);
  const vision::CadModel& m = scene->model;
  CHECK(m.faces.size() == 32);
  REQUIRE(m.circles.size() == 2);
  CHECK(m.circles[0].radius_m == Approx(0.04));
  CHECK(m.circles[1].centre_obj.z() == Approx(0.12));
  check_facets_below_crease(m);
  // The render is much finer than the model (smooth, not a 32-gon).
  CHECK(scene->object_mesh.triangles.size() > 8 * m.faces.size() * 2);
  int textured = 0;
  for (const auto& mat : scene->materials) textured += mat.texture >= 0;
  CHECK(textured >= 1);
  CHECK(scene->occluders.empty());
}

TEST_CASE("bowl: 4 rings of 32 facets below the crease angle, an open top with its rim circle", "[scene_library]") {
  auto scene = sim::make_scene("bowl");
  REQUIRE(scene);
  const vision::CadModel& m = scene->model;
  CHECK(m.faces.size() == 4 * 32);
  CHECK_FALSE(m.closed);
  REQUIRE(m.circles.size() == 1);
  CHECK(m.circles[0].normal_obj.z() == Approx(1));
  // Curved profile: the facets' slope changes from ring to ring.
  CHECK(std::abs(m.faces[0].normal_obj.z()) > std::abs(m.faces[3 * 32].normal_obj.z()) + 0.3);
  check_facets_below_crease(m);
  // Every model vertex lies on the rendered surface's profile (to the 32-gon's sagitta).
  for (const auto& p : m.vertices) CHECK(p.head<2>().norm() <= m.circles[0].radius_m + 1e-9);
  CHECK_FALSE(scene->object_mesh.closed);
}

TEST_CASE("box_clutter: a 20 x 15 x 10 cm textured box over photographs", "[scene_library]") {
  auto scene = sim::make_scene("box_clutter");
  REQUIRE(scene);
  Eigen::AlignedBox3d box;
  for (const auto& p : scene->model.vertices) box.extend(p);
  const Eigen::Vector3d size = box.sizes();
  CHECK(size.x() == Approx(0.20));
  CHECK(size.y() == Approx(0.15));
  CHECK(size.z() == Approx(0.10));
  CHECK(scene->model.closed);
  int textured = 0;
  for (const auto& mat : scene->materials) textured += mat.texture >= 0;
  CHECK(textured >= 6);
  int photo_planes = 0;
  for (const auto& p : scene->background.planes) photo_planes += p.texture >= 0;
  CHECK(photo_planes >= 4);
}

TEST_CASE("office_pan: a room corner of a few metres with a door frame and a desk", "[scene_library]") {
  auto scene = sim::make_scene("office_pan");
  REQUIRE(scene);
  Eigen::AlignedBox3d box;
  for (const auto& p : scene->model.vertices) box.extend(p);
  CHECK(box.sizes().x() >= 3.0);
  CHECK(box.sizes().y() >= 2.5);
  CHECK(box.sizes().z() >= 2.0);
  CHECK(scene->model.faces.size() >= 3 + 8 * 6);
  CHECK(scene->view.distance_m >= 2.0);
}

TEST_CASE("an unknown scene name is an error that lists the known ones", "[scene_library]") {
  auto scene = sim::make_scene("teapot");
  REQUIRE_FALSE(scene);
  CHECK(scene.error().find("teapot") != std::string::npos);
  CHECK(scene.error().find("box_clutter") != std::string::npos);
  CHECK_FALSE(sim::make_scene_model("teapot"));
}
