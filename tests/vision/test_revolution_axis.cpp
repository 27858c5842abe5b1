// Bodies of revolution: the axis of a facetted cone with its rims is found wherever the cone
// stands, models that only look round somewhere (a box with a circle, an off-axis rim, too few
// or uneven facets, no circle) are not taken for one, and the turn's twist moves the pose as
// turning the object about its axis does.
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include "epichead/geometry/se3.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/revolution_axis.h"

using namespace epichead::vision;
namespace geometry = epichead::geometry;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

struct ConeSpec {
  int facets = 32;
  double bottom_radius_m = 0.09, top_radius_m = 0.06, height_m = 0.14;
  bool circles = true;
  Eigen::Vector3d top_circle_shift_m = Eigen::Vector3d::Zero();  // moves the top rim off the axis
  bool top_circle_first = false;                                 // the off-axis rim proposes the axis
  double uneven_rad = 0;  // added to the angle of every other vertex of each ring
  Eigen::Isometry3d world_T_cone = Eigen::Isometry3d::Identity();  // moves and tilts the whole model
};

// A lampshade-like cone about z: two rings of vertices, quads between them, the two rims
// (as sim/src/scene_models.cpp models the lampshade), all moved by spec.world_T_cone.
RawModel cone_raw(const ConeSpec& spec) {
  RawModel raw;
  const Eigen::Isometry3d& T = spec.world_T_cone;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < spec.facets; ++i) {
      const double a = 2 * std::numbers::pi * i / spec.facets + (i % 2 == 1 ? spec.uneven_rad : 0.0);
      const double r = ring == 0 ? spec.bottom_radius_m : spec.top_radius_m;
      raw.vertices.push_back(T * Eigen::Vector3d(r * std::cos(a), r * std::sin(a), ring == 0 ? 0.0 : spec.height_m));
    }
  for (int i = 0; i < spec.facets; ++i) {
    const int j = (i + 1) % spec.facets;
    raw.face_loops.push_back({i, j, spec.facets + j, spec.facets + i});
  }
  if (spec.circles) {
    const ModelCircle bottom{T * Eigen::Vector3d::Zero(), T.linear() * -Eigen::Vector3d::UnitZ(), spec.bottom_radius_m};
    const ModelCircle top{T * (Eigen::Vector3d(0, 0, spec.height_m) + spec.top_circle_shift_m),
                          T.linear() * Eigen::Vector3d::UnitZ(), spec.top_radius_m};
    if (spec.top_circle_first) {
      raw.circles = {top, bottom};
    } else {
      raw.circles = {bottom, top};
    }
  }
  return raw;
}

CadModel cone(const ConeSpec& spec) {
  auto model = build_model(cone_raw(spec), "cone");
  REQUIRE(model.has_value());
  return *model;
}

// Distance of p from the line through `point` along unit `direction`.
double distance_from_line(const Eigen::Vector3d& p, const Eigen::Vector3d& point, const Eigen::Vector3d& direction) {
  const Eigen::Vector3d d = p - point;
  return (d - d.dot(direction) * direction).norm();
}

Eigen::Isometry3d moved_and_tilted() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()) *
                Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitX())).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.35, -0.2, 1.3);
  return T;
}

}  // namespace

TEST_CASE("the axis of a facetted cone with its two rims is the z axis") {
  const CadModel model = cone({});
  const auto axis = find_revolution_axis(model);
  REQUIRE(axis.has_value());
  CHECK(axis->direction_obj.norm() == Approx(1.0).epsilon(1e-12));
  CHECK(std::abs(axis->direction_obj.z()) == Approx(1.0).epsilon(1e-12));
  CHECK(axis->direction_obj.head<2>().norm() < 1e-9);
  CHECK(axis->point_obj.head<2>().norm() < 1e-9);  // on the z axis, anywhere along it
}

TEST_CASE("the axis of a moved and tilted cone is the moved and tilted axis") {
  ConeSpec spec;
  spec.world_T_cone = moved_and_tilted();
  const auto axis = find_revolution_axis(cone(spec));
  REQUIRE(axis.has_value());
  const Eigen::Vector3d expected_point = spec.world_T_cone * Eigen::Vector3d::Zero();
  const Eigen::Vector3d expected_direction = spec.world_T_cone.linear() * Eigen::Vector3d::UnitZ();
  CHECK(axis->direction_obj.norm() == Approx(1.0).epsilon(1e-12));
  CHECK(axis->direction_obj.cross(expected_direction).norm() < 1e-9);
  CHECK(distance_from_line(axis->point_obj, expected_point, expected_direction) < 1e-9);
  // The untransformed z axis is not it.
  CHECK(std::abs(axis->direction_obj.z()) < 0.99);
}

TEST_CASE("a can modelled with a cylinder instead of rims has the cylinder's axis") {
  ConeSpec spec;
  spec.circles = false;
  spec.top_radius_m = spec.bottom_radius_m;
  spec.world_T_cone = moved_and_tilted();
  RawModel raw = cone_raw(spec);
  raw.cylinders.push_back({spec.world_T_cone * Eigen::Vector3d::Zero(),
                           spec.world_T_cone * Eigen::Vector3d(0, 0, spec.height_m), spec.bottom_radius_m});
  auto model = build_model(raw, "can");
  REQUIRE(model.has_value());
  const auto axis = find_revolution_axis(*model);
  REQUIRE(axis.has_value());
  const Eigen::Vector3d expected_direction = spec.world_T_cone.linear() * Eigen::Vector3d::UnitZ();
  CHECK(axis->direction_obj.cross(expected_direction).norm() < 1e-9);
  CHECK(distance_from_line(axis->point_obj, spec.world_T_cone.translation(), expected_direction) < 1e-9);
}

TEST_CASE("a box with a centred circle on a face is not a body of revolution (4 vertices per ring)") {
  // A square box whose vertices do form rings of four evenly spaced about the circle's axis:
  // only the ring size tells it from a body of revolution.
  RawModel raw;
  const double h = 0.05;
  for (int z = 0; z < 2; ++z)
    for (const auto& xy : {Eigen::Vector2d(-h, -h), Eigen::Vector2d(h, -h), Eigen::Vector2d(h, h), Eigen::Vector2d(-h, h)})
      raw.vertices.emplace_back(xy.x(), xy.y(), z * 0.08);
  raw.face_loops = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  raw.circles.push_back({Eigen::Vector3d(0, 0, 0.08), Eigen::Vector3d::UnitZ(), 0.03});
  auto model = build_model(raw, "box");
  REQUIRE(model.has_value());
  CHECK_FALSE(find_revolution_axis(*model).has_value());
  CHECK(find_revolution_axis(*model, 4).has_value());  // the rings themselves are regular
}

TEST_CASE("a cone whose rim circle is off the axis is not a body of revolution") {
  ConeSpec spec;
  spec.top_circle_shift_m = Eigen::Vector3d(0.01, 0, 0);
  CHECK_FALSE(find_revolution_axis(cone(spec)).has_value());
  spec.top_circle_first = true;  // the off-axis rim proposes the axis: the other rim and the rings refuse it
  CHECK_FALSE(find_revolution_axis(cone(spec)).has_value());
  // The same rim tilted instead of shifted.
  ConeSpec tilted;
  RawModel raw = cone_raw(tilted);
  raw.circles[1].normal_obj = Eigen::AngleAxisd(5 * kDeg, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  auto model = build_model(raw, "cone");
  REQUIRE(model.has_value());
  CHECK_FALSE(find_revolution_axis(*model).has_value());
}

TEST_CASE("a facetted cone without circles or cylinders gives no axis") {
  ConeSpec spec;
  spec.circles = false;
  CHECK_FALSE(find_revolution_axis(cone(spec)).has_value());
}

TEST_CASE("a cone of 6 facets is not a body of revolution, unless fewer ring vertices are asked for") {
  ConeSpec spec;
  spec.facets = 6;
  const CadModel model = cone(spec);
  CHECK_FALSE(find_revolution_axis(model).has_value());
  CHECK(find_revolution_axis(model, 6).has_value());
  spec.facets = 8;  // the fewest the default accepts
  CHECK(find_revolution_axis(cone(spec)).has_value());
}

TEST_CASE("unevenly spaced ring vertices give no axis") {
  ConeSpec spec;
  spec.uneven_rad = 2 * kDeg;  // every other vertex 2 degrees off its place
  CHECK_FALSE(find_revolution_axis(cone(spec)).has_value());
  spec.uneven_rad = 0.5 * kDeg;
  CHECK_FALSE(find_revolution_axis(cone(spec)).has_value());
}

TEST_CASE("the revolution twist turns the pose about the object's axis to first order") {
  // An axis that does not pass through the object origin, so the twist's translation part matters.
  RevolutionAxis axis;
  axis.point_obj = Eigen::Vector3d(0.04, -0.03, 0.05);
  axis.direction_obj = Eigen::Vector3d(0.2, -0.1, 1).normalized();
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  cam_T_obj.linear() = (Eigen::AngleAxisd(2.0, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()))
                           .toRotationMatrix();
  cam_T_obj.translation() = Eigen::Vector3d(0.05, 0.1, 0.6);

  const Eigen::Matrix<double, 6, 1> u = revolution_twist(axis, cam_T_obj);
  CHECK(u.tail<3>().norm() == Approx(1.0).epsilon(1e-12));
  CHECK((u.tail<3>() - cam_T_obj.linear() * axis.direction_obj).norm() < 1e-12);
  CHECK(u.head<3>().norm() > 0.1);  // not the turn about the camera origin

  const double theta = 1e-6;
  const Eigen::Isometry3d obj_T_turned = Eigen::Translation3d(axis.point_obj) * Eigen::AngleAxisd(theta, axis.direction_obj) *
                                         Eigen::Translation3d(-axis.point_obj);
  const Eigen::Isometry3d expected = cam_T_obj * obj_T_turned;
  const Eigen::Isometry3d got = geometry::apply_left(theta * u, cam_T_obj);
  const double moved_m = (expected.translation() - cam_T_obj.translation()).norm();
  REQUIRE(moved_m > 1e-8);  // the turn does move the origin
  CHECK((got.translation() - expected.translation()).norm() < 1e-9 * cam_T_obj.translation().norm());
  CHECK((got.linear() - expected.linear()).norm() < 1e-9);
  // Relative to the motion itself: right to first order, not just small.
  CHECK((got.translation() - expected.translation()).norm() < 1e-3 * moved_m);
  CHECK((got.linear() - expected.linear()).norm() < 1e-3 * (expected.linear() - cam_T_obj.linear()).norm());
  // Points of the object land where the turned object's points are.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0, 0.2, -0.1), axis.point_obj})
    CHECK((got * p - expected * p).norm() < 1e-3 * theta * 0.3 + 1e-15);
}
