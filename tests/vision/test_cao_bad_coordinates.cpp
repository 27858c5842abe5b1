// Coordinates, radii and load() translations no physical model has (beyond kMaxModelExtentM, or
// not finite) are errors naming the line; build_model refuses them too, so the topology never
// computes with non-finite lengths (a NaN cast to a grid cell was undefined behaviour).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "common/temp_dir.h"
#include "epichead/vision/cao_model.h"

using namespace epichead::vision;

namespace {

// A tetrahedron with point 1 at (x, 0, 0), a cylinder of radius `cyl_r` and a circle of
// radius `circle_r`.
std::string tetra(const std::string& x, const std::string& cyl_r = "0.01", const std::string& circle_r = "0.02") {
  return "V1\n4\n0 0 0\n" + x + " 0 0\n0 0.1 0\n0 0 0.1\n0\n0\n4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n1\n0 3 " + cyl_r +
         "\n1\n" + circle_r + " 0 1 2\n";
}

std::string parse_error(const std::string& text, const std::string& base_dir = ".") {
  auto m = parse_cao(text, "m.cao", base_dir);
  REQUIRE_FALSE(m.has_value());
  return m.error();
}

}  // namespace

TEST_CASE("A model at the physical bound loads, with finite parallel-pair distances") {
  auto m = parse_cao(tetra("1e6"), "m.cao");
  REQUIRE(m.has_value());
  for (const auto& pair : m->parallel_pairs) CHECK(std::isfinite(pair.distance_m));
}

TEST_CASE("Coordinates beyond 1e6 m are an error naming the line") {
  CHECK_THAT(parse_error(tetra("1e308")), Catch::Contains("m.cao:4: coordinate X of point 1 '1e308' is beyond the 1e6 m"));
  CHECK_THAT(parse_error(tetra("-1e308")), Catch::Contains("m.cao:4:") && Catch::Contains("beyond"));
  CHECK_THAT(parse_error(tetra("1000001")), Catch::Contains("m.cao:4:") && Catch::Contains("beyond"));
  CHECK_THAT(parse_error(tetra("1e999")), Catch::Contains("m.cao:4:") && Catch::Contains("a finite number"));
  CHECK_THAT(parse_error(tetra("nan")), Catch::Contains("m.cao:4:") && Catch::Contains("a finite number"));
}

TEST_CASE("Radii beyond 1e6 m are an error naming the line") {
  CHECK_THAT(parse_error(tetra("0.1", "1e300")), Catch::Contains("m.cao:15: radius '1e300' is beyond"));
  CHECK_THAT(parse_error(tetra("0.1", "0.01", "2e6")), Catch::Contains("m.cao:17: radius '2e6' is beyond"));
}

TEST_CASE("load() translations beyond 1e6 m, and points they move beyond it, are errors") {
  epichead::testing::TempDir dir("epichead_test_cao_bad");
  dir.write("part.cao", tetra("0.1"));
  CHECK_THAT(parse_error("V1\nload(\"part.cao\", t=[0;0;1e308])\n0\n0\n0\n0\n0\n0\n", dir.str()),
             Catch::Contains("m.cao:2: load() translation") && Catch::Contains("beyond"));
  CHECK_THAT(parse_error("V1\nload(\"part.cao\", t=[0;0;1e6])\n0\n0\n0\n0\n0\n0\n", dir.str()),
             Catch::Contains("part.cao:") && Catch::Contains("lies beyond the 1e6 m") && Catch::Contains("load() transforms"));
  auto ok = parse_cao("V1\nload(\"part.cao\", t=[0;0;1e5])\n0\n0\n0\n0\n0\n0\n", "m.cao", dir.str());
  CHECK(ok.has_value());
}

TEST_CASE("build_model refuses points, circles and cylinders beyond the bound or not finite") {
  RawModel raw;
  raw.vertices = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.1, 0}};
  raw.face_loops = {{0, 1, 2}};
  REQUIRE(build_model(raw).has_value());
  RawModel far = raw;
  far.vertices[1].x() = 1e308;
  CHECK_THAT(build_model(far).error(), Catch::Contains("point 1 is beyond the 1e6 m"));
  RawModel nan = raw;
  nan.vertices[2].y() = std::numeric_limits<double>::quiet_NaN();
  CHECK_THAT(build_model(nan).error(), Catch::Contains("point 2 is not finite"));
  RawModel circle = raw;
  circle.circles.push_back({Eigen::Vector3d(0, 0, 1e7), Eigen::Vector3d::UnitZ(), 0.1});
  CHECK_THAT(build_model(circle).error(), Catch::Contains("circle 0: centre or radius is beyond"));
  RawModel cylinder = raw;
  cylinder.cylinders.push_back({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitZ(), 1e9});
  CHECK_THAT(build_model(cylinder).error(), Catch::Contains("cylinder 0: axis or radius is beyond"));
}
