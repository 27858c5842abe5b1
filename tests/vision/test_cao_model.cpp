// CAO reader and model topology: the real tea box, every section of the format, load()
// includes, every error path (with file:line), warnings, and the to_cao round trip.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <string>

#include <unistd.h>

#include <Eigen/Geometry>

#include "epichead/vision/cao_model.h"
#include "epichead/vision/model_centre.h"

using epichead::vision::build_model;
using epichead::vision::CadModel;
using epichead::vision::load_cao;
using epichead::vision::ModelCircle;
using epichead::vision::ModelEdge;
using epichead::vision::ModelFace;
using epichead::vision::parse_cao;
using epichead::vision::RawModel;
using epichead::vision::to_cao;

namespace {

const std::string kData = std::string(EPICHEAD_TEST_DATA) + "/cao/";

CadModel load_ok(const std::string& path) {
  auto m = load_cao(path);
  INFO(path << ": " << (m ? std::string("ok") : m.error()));
  REQUIRE(m.has_value());
  return *m;
}

CadModel parse_ok(const std::string& text) {
  auto m = parse_cao(text, "t.cao");
  INFO((m ? std::string("ok") : m.error()));
  REQUIRE(m.has_value());
  return *m;
}

std::string parse_error(const std::string& text) {
  auto m = parse_cao(text, "t.cao");
  REQUIRE_FALSE(m.has_value());
  return m.error();
}

bool has_warning(const CadModel& m, const std::string& part) {
  return std::any_of(m.warnings.begin(), m.warnings.end(),
                     [&](const std::string& w) { return w.find(part) != std::string::npos; });
}

Eigen::Vector3d face_centroid(const CadModel& m, const ModelFace& f) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int v : f.vertices) c += m.vertices[v];
  return c / static_cast<double>(f.vertices.size());
}

double triangle_area(const CadModel& m, const std::array<int, 3>& t, const Eigen::Vector3d& normal) {
  return 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).dot(normal);
}

double polygon_area(const CadModel& m, const ModelFace& f) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < f.vertices.size(); ++i) {
    sum += m.vertices[f.vertices[i]].cross(m.vertices[f.vertices[(i + 1) % f.vertices.size()]]);
  }
  return 0.5 * sum.norm();
}

// Invariants of every well-formed face and edge: unit normals on the face plane, triangles
// CCW from outside that tile the face, into_face unit, in the plane, normal to the edge and
// pointing toward the face.
void check_geometry(const CadModel& m) {
  for (const ModelFace& f : m.faces) {
    CHECK(f.normal_obj.norm() == Approx(1).epsilon(1e-12));
    for (int v : f.vertices) CHECK(f.normal_obj.dot(m.vertices[v]) == Approx(f.offset_m).margin(1e-12));
    CHECK(f.triangles.size() == f.vertices.size() - 2);
    double area = 0;
    for (const auto& t : f.triangles) {
      const double a = triangle_area(m, t, f.normal_obj);
      CHECK(a > 0);  // CCW seen from outside, like the face
      area += a;
    }
    CHECK(area == Approx(polygon_area(m, f)).epsilon(1e-9));
  }
  for (const ModelEdge& e : m.edges) {
    const Eigen::Vector3d d = (m.vertices[e.v1] - m.vertices[e.v0]).normalized();
    for (int k = 0; k < e.face_count(); ++k) {
      const ModelFace& f = m.faces[e.faces[k]];
      const Eigen::Vector3d& into = e.into_face[k];
      CHECK(into.norm() == Approx(1).epsilon(1e-12));
      CHECK(std::abs(into.dot(d)) < 1e-12);
      CHECK(std::abs(into.dot(f.normal_obj)) < 1e-12);
      CHECK(into.dot(face_centroid(m, f) - m.vertices[e.v0]) > 0);  // true for convex faces
    }
  }
}

void check_box_topology(const CadModel& m) {
  CHECK(m.vertices.size() == 8);
  CHECK(m.faces.size() == 6);
  CHECK(m.edges.size() == 12);
  for (const ModelEdge& e : m.edges) {
    CHECK(e.face_count() == 2);
    CHECK(e.extra_faces == 0);
    CHECK(e.faces[0] != e.faces[1]);
  }
  CHECK(m.closed);
  REQUIRE(m.junctions.size() == 8);
  for (const auto& j : m.junctions) CHECK(j.edges.size() == 3);
  // 3 directions x C(4, 2) pairs of the 4 parallel edges in each.
  CHECK(m.parallel_pairs.size() == 18);
  // Normals point away from the centre of the box.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& v : m.vertices) centre += v / 8.0;
  for (const ModelFace& f : m.faces) CHECK(f.normal_obj.dot(face_centroid(m, f) - centre) > 0);
  check_geometry(m);
  CHECK(m.warnings.empty());
}

void check_same_model(const CadModel& a, const CadModel& b) {
  REQUIRE(a.vertices.size() == b.vertices.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i) CHECK(a.vertices[i] == b.vertices[i]);
  REQUIRE(a.faces.size() == b.faces.size());
  for (std::size_t i = 0; i < a.faces.size(); ++i) {
    CHECK(a.faces[i].vertices == b.faces[i].vertices);
    CHECK(a.faces[i].normal_obj.isApprox(b.faces[i].normal_obj, 1e-12));
    CHECK(a.faces[i].offset_m == Approx(b.faces[i].offset_m).margin(1e-12));
    CHECK(a.faces[i].triangles == b.faces[i].triangles);
  }
  REQUIRE(a.edges.size() == b.edges.size());
  for (std::size_t i = 0; i < a.edges.size(); ++i) {
    CHECK(a.edges[i].v0 == b.edges[i].v0);
    CHECK(a.edges[i].v1 == b.edges[i].v1);
    CHECK(a.edges[i].faces == b.edges[i].faces);
    CHECK(a.edges[i].extra_faces == b.edges[i].extra_faces);
    for (int k = 0; k < 2; ++k) CHECK((a.edges[i].into_face[k] - b.edges[i].into_face[k]).norm() < 1e-12);
  }
  REQUIRE(a.circles.size() == b.circles.size());
  for (std::size_t i = 0; i < a.circles.size(); ++i) {
    CHECK((a.circles[i].centre_obj - b.circles[i].centre_obj).norm() < 1e-12);
    CHECK((a.circles[i].normal_obj - b.circles[i].normal_obj).norm() < 1e-12);
    CHECK(a.circles[i].radius_m == b.circles[i].radius_m);
  }
  REQUIRE(a.cylinders.size() == b.cylinders.size());
  for (std::size_t i = 0; i < a.cylinders.size(); ++i) {
    CHECK(a.cylinders[i].axis_a_obj == b.cylinders[i].axis_a_obj);
    CHECK(a.cylinders[i].axis_b_obj == b.cylinders[i].axis_b_obj);
    CHECK(a.cylinders[i].radius_m == b.cylinders[i].radius_m);
  }
  REQUIRE(a.junctions.size() == b.junctions.size());
  for (std::size_t i = 0; i < a.junctions.size(); ++i) {
    CHECK(a.junctions[i].vertex == b.junctions[i].vertex);
    CHECK(a.junctions[i].edges == b.junctions[i].edges);
  }
  REQUIRE(a.parallel_pairs.size() == b.parallel_pairs.size());
  for (std::size_t i = 0; i < a.parallel_pairs.size(); ++i) {
    CHECK(a.parallel_pairs[i].edge_a == b.parallel_pairs[i].edge_a);
    CHECK(a.parallel_pairs[i].edge_b == b.parallel_pairs[i].edge_b);
    CHECK(a.parallel_pairs[i].distance_m == Approx(b.parallel_pairs[i].distance_m).margin(1e-12));
  }
  CHECK(a.closed == b.closed);
}

// The minimal sections after the points, for error tests.
const std::string kTail = "0\n0\n0\n0\n0\n";

}  // namespace

TEST_CASE("the real tea box model loads as a closed box with outward normals") {
  const CadModel m = load_ok(std::string(EPICHEAD_SHARED_DATA) + "/teabox/model.cao");
  check_box_topology(m);
  std::multiset<long> distances_um;
  for (const auto& p : m.parallel_pairs) distances_um.insert(std::lround(p.distance_m * 1e6));
  // Box 0.165 x 0.068 x 0.08: each direction has two pairs per side distance and two diagonals.
  CHECK(distances_um.count(68000) == 4);   // x edges across y, z edges across y
  CHECK(distances_um.count(80000) == 4);   // x edges across z, y edges across z
  CHECK(distances_um.count(165000) == 4);  // y and z edges across x
  CHECK(distances_um.count(std::lround(std::hypot(0.068, 0.08) * 1e6)) == 2);
  CHECK(distances_um.count(std::lround(std::hypot(0.165, 0.08) * 1e6)) == 2);
  CHECK(distances_um.count(std::lround(std::hypot(0.165, 0.068) * 1e6)) == 2);
  // Face 0 lies in y = 0 with the box on the +y side.
  CHECK(m.faces[0].normal_obj.isApprox(Eigen::Vector3d(0, -1, 0)));
  CHECK(m.faces[0].offset_m == Approx(0).margin(1e-15));
}

TEST_CASE("the second tea box sequence's model loads as a closed box") {
  check_box_topology(load_ok(std::string(EPICHEAD_SHARED_DATA) + "/teabox_left/model.cao"));
}

TEST_CASE("model_centre: the mean of the vertices, the origin for a model without any") {
  CHECK(epichead::vision::model_centre(load_ok(kData + "cube.cao")).isApprox(Eigen::Vector3d(0.05, 0.05, 0.05)));
  CHECK(epichead::vision::model_centre(CadModel{}) == Eigen::Vector3d::Zero());
}

TEST_CASE("the cube fixture is a closed unit box with axis normals") {
  const CadModel m = load_ok(kData + "cube.cao");
  check_box_topology(m);
  const Eigen::Vector3d expected[6] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
  const double offsets[6] = {0, 0.1, 0, 0.1, 0.1, 0};
  for (int f = 0; f < 6; ++f) {
    CHECK(m.faces[f].normal_obj.isApprox(expected[f]));
    CHECK(m.faces[f].offset_m == Approx(offsets[f]).margin(1e-15));
  }
  // Edge 0-3 is the first side of face 0 (bottom) and lies on face 5 (x = 0): the bottom is on
  // its +x side, the x = 0 face on its +z side.
  const auto it = std::find_if(m.edges.begin(), m.edges.end(), [](const ModelEdge& e) {
    return (e.v0 == 0 && e.v1 == 3) || (e.v0 == 3 && e.v1 == 0);
  });
  REQUIRE(it != m.edges.end());
  CHECK(it->faces[0] == 0);
  CHECK(it->faces[1] == 5);
  CHECK(it->into_face[0].isApprox(Eigen::Vector3d(1, 0, 0)));
  CHECK(it->into_face[1].isApprox(Eigen::Vector3d(0, 0, 1)));
}

TEST_CASE("the L-shaped prism has non-convex end faces, triangulated without covering the notch") {
  const CadModel m = load_ok(kData + "l_shape.cao");
  CHECK(m.vertices.size() == 12);
  REQUIRE(m.faces.size() == 8);
  CHECK(m.edges.size() == 18);
  CHECK(m.closed);
  CHECK(m.warnings.empty());
  REQUIRE(m.junctions.size() == 12);
  for (const auto& j : m.junctions) CHECK(j.edges.size() == 3);
  const Eigen::Vector3d expected[8] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {1, 0, 0},
                                       {0, 1, 0},  {1, 0, 0}, {0, 1, 0},  {-1, 0, 0}};
  for (int f = 0; f < 8; ++f) CHECK(m.faces[f].normal_obj.isApprox(expected[f]));
  for (int f : {0, 1}) {
    const ModelFace& face = m.faces[f];
    CHECK(face.triangles.size() == 4);
    double area = 0;
    for (const auto& t : face.triangles) area += triangle_area(m, t, face.normal_obj);
    CHECK(area == Approx(0.03));
    // The notch centre (0.15, 0.15) is in no triangle.
    for (const auto& t : face.triangles) {
      const Eigen::Vector2d p(0.15, 0.15);
      bool inside = true;
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d a = m.vertices[t[k]], b = m.vertices[t[(k + 1) % 3]];
        const double side = (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
        inside = inside && side * face.normal_obj.z() > 0;
      }
      CHECK_FALSE(inside);
    }
  }
  // The inner vertical edge 3-9 joins the short arm's top (y = 0.1, lying at x > 0.1) and the
  // inner side (x = 0.1, lying at y > 0.1).
  const auto it = std::find_if(m.edges.begin(), m.edges.end(), [](const ModelEdge& e) {
    return std::min(e.v0, e.v1) == 3 && std::max(e.v0, e.v1) == 9;
  });
  REQUIRE(it != m.edges.end());
  CHECK(it->faces == std::array<int, 2>{4, 5});
  CHECK(it->into_face[0].isApprox(Eigen::Vector3d(1, 0, 0)));
  CHECK(it->into_face[1].isApprox(Eigen::Vector3d(0, 1, 0)));
  // Geometry invariants (the centroid test of into_face holds here for all but the L faces).
  for (const ModelFace& f : m.faces) {
    CHECK(f.triangles.size() == f.vertices.size() - 2);
    for (int v : f.vertices) CHECK(f.normal_obj.dot(m.vertices[v]) == Approx(f.offset_m).margin(1e-12));
  }
}

TEST_CASE("faces from 3D lines chain into the same vertex loops as faces from points") {
  const CadModel from_lines = load_ok(kData + "cube_from_lines.cao");
  const CadModel from_points = load_ok(kData + "cube.cao");
  check_box_topology(from_lines);  // the 12 lines merge into the face edges: no extra edges
  check_same_model(from_lines, from_points);
}

TEST_CASE("free lines, cylinders and circles are read with ViSP's field order, attributes skipped") {
  const CadModel m = load_ok(kData + "wire_and_round.cao");
  CHECK(m.vertices.size() == 8);
  CHECK(m.faces.empty());
  REQUIRE(m.edges.size() == 2);
  CHECK(m.edges[0].v0 == 4);
  CHECK(m.edges[0].v1 == 5);
  CHECK(m.edges[1].v0 == 0);
  CHECK(m.edges[1].v1 == 4);
  for (const ModelEdge& e : m.edges) CHECK(e.face_count() == 0);
  CHECK_FALSE(m.closed);
  REQUIRE(m.junctions.size() == 1);
  CHECK(m.junctions[0].vertex == 4);
  CHECK(m.junctions[0].edges == std::vector<int>{0, 1});
  CHECK(m.parallel_pairs.empty());
  REQUIRE(m.cylinders.size() == 1);
  CHECK(m.cylinders[0].axis_a_obj == Eigen::Vector3d(0, 0, 0));
  CHECK(m.cylinders[0].axis_b_obj == Eigen::Vector3d(0, 0, 0.2));
  CHECK(m.cylinders[0].radius_m == 0.05);
  REQUIRE(m.circles.size() == 2);
  CHECK(m.circles[0].radius_m == 0.05);
  CHECK(m.circles[0].centre_obj == Eigen::Vector3d(0, 0, 0));
  CHECK(m.circles[0].normal_obj.isApprox(Eigen::Vector3d(0, 0, 1)));
  CHECK(m.circles[1].centre_obj == Eigen::Vector3d(0, 0, 0.2));
  CHECK(m.circles[1].normal_obj.isApprox(Eigen::Vector3d(0, 0, -1)));
}

TEST_CASE("files without the cylinder and circle sections (older ViSP files) load") {
  const CadModel m = parse_ok("V1\n3\n0 0 0\n1 0 0\n0 1 0\n0\n0\n1\n3 0 1 2\n");
  CHECK(m.faces.size() == 1);
  CHECK(parse_ok("V1\n3\n0 0 0\n1 0 0\n0 1 0\n0\n0\n1\n3 0 1 2\n1\n0 1 0.5\n").cylinders.size() == 1);
}

TEST_CASE("tokens may be spread over lines, and # and // comments are skipped anywhere") {
  const CadModel m = parse_ok(
      "# header comment\n  V1 # version\n3 0 0 0 1 0 0\n0 1\n0 // ViSP's documentation style\n"
      "0 0#none\n1 3\n0\n1\n2 0 0");
  REQUIRE(m.faces.size() == 1);
  CHECK(m.faces[0].vertices == std::vector<int>{0, 1, 2});
  CHECK(m.vertices[2] == Eigen::Vector3d(0, 1, 0));
}

TEST_CASE("V2 files carry two image coordinates per point, which are skipped") {
  const CadModel m = parse_ok("V2\n3\n0 0 0 10 20\n1 0 0 11 21\n0 1 0 12 22\n0\n0\n1\n3 0 1 2\n0\n0\n");
  CHECK(m.vertices[1] == Eigen::Vector3d(1, 0, 0));
}

TEST_CASE("load() includes files relative to the including file, appends their points with an offset, "
          "and applies t and tu") {
  const CadModel m = load_ok(kData + "include_main.cao");
  // cube (0-7), moved cube (8-15), triangle.cao's cube (16-23), triangle.cao (24-26), main (27-29)
  REQUIRE(m.vertices.size() == 30);
  REQUIRE(m.faces.size() == 20);
  CHECK(m.vertices[1] == Eigen::Vector3d(0.1, 0, 0));
  CHECK((m.vertices[9] - Eigen::Vector3d(1, 0.1, 0)).norm() < 1e-15);  // Rz(90 deg) then +1 m in x
  CHECK(m.vertices[16] == Eigen::Vector3d(0, 0, -1));
  CHECK(m.vertices[24] == Eigen::Vector3d(0, 0, 2));
  CHECK(m.vertices[27] == Eigen::Vector3d(0, 0, 1));
  CHECK(m.faces[6].vertices == std::vector<int>{8, 11, 10, 9});
  CHECK(m.faces[18].vertices == std::vector<int>{24, 25, 26});
  CHECK(m.faces[19].vertices == std::vector<int>{27, 28, 29});
  // triangle.cao's free line 0-1 is its face's first side: merged, not a new edge.
  CHECK(m.edges.size() == 3 * 12 + 3 + 3);
  CHECK(m.closed == false);  // the triangles are open surfaces
  for (int f = 0; f < 18; ++f) CHECK(m.faces[f].normal_obj.norm() == Approx(1));
}

TEST_CASE("parse_cao resolves load() against base_dir") {
  const CadModel m =
      *parse_cao("V1\nload(\"cube.cao\")\n0\n0\n0\n0\n0\n0\n", "mem.cao", std::string(EPICHEAD_TEST_DATA) + "/cao");
  CHECK(m.vertices.size() == 8);
  CHECK(m.closed);
}

TEST_CASE("a load() cycle is an error naming the chain of files") {
  auto m = load_cao(kData + "cycle_a.cao");
  REQUIRE_FALSE(m.has_value());
  const std::string a = kData + "cycle_a.cao", b = kData + "cycle_b.cao";
  CHECK(m.error() == b + ":3: load() cycle: " + a + " -> " + b + " -> " + a);
}

TEST_CASE("load() nesting deeper than the limit is an error, not a stack overflow") {
  const auto dir = std::filesystem::temp_directory_path() / ("epichead_cao_depth_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 40; ++i) {
    std::ofstream(dir / ("d" + std::to_string(i) + ".cao"))
        << "V1\nload(\"d" << i + 1 << ".cao\")\n0\n0\n0\n0\n";
  }
  std::ofstream(dir / "d40.cao") << "V1\n0\n0\n0\n0\n";
  auto m = load_cao((dir / "d0.cao").string());
  std::filesystem::remove_all(dir);
  REQUIRE_FALSE(m.has_value());
  CHECK(m.error().find(":2: load() nested deeper than 16 files") != std::string::npos);
}

TEST_CASE("load() syntax errors and missing files name the line") {
  const std::string dir = std::string(EPICHEAD_TEST_DATA) + "/cao";
  auto error = [&](const std::string& text) {
    auto m = parse_cao(text, "t.cao", dir);
    REQUIRE_FALSE(m.has_value());
    return m.error();
  };
  CHECK(error("V1\nload cube.cao\n") == "t.cao:2: expected load(\"file.cao\")");
  CHECK(error("V1\nload(cube.cao)\n") == "t.cao:2: expected a quoted file name in load()");
  CHECK(error("V1\nload(\"cube.cao)\n") == "t.cao:2: missing closing '\"' in load()");
  CHECK(error("V1\nload(\"cube.cao\"\n") == "t.cao:2: missing ')' closing load()");
  CHECK(error("V1\n\nload(\"cube.cao\", t=[1;2])\n") ==
        "t.cao:3: expected t=[x;y;z] or tu=[rx;ry;rz] in load(), got 't=[1;2]'");
  CHECK(error("V1\nload(\"nothere.cao\")\n").starts_with("t.cao:2: load(): "));
  CHECK(error("V1\nload(\"nothere.cao\")\n").ends_with("nothere.cao: cannot open (no such file)"));
  // An error inside an included file names that file and its line.
  CHECK(error("V1\nload(\"cycle_b.cao\")\n0\n0\n0\n0\n").find("cycle_a.cao:2: load() cycle") != std::string::npos);
  // Unknown load() parameters are skipped.
  CHECK(parse_cao("V1\nload(\"cube.cao\", scale=2)\n0\n0\n0\n0\n", "t.cao", dir).has_value());
}

TEST_CASE("a missing file is an error naming it") {
  auto m = load_cao("/nonexistent/model.cao");
  REQUIRE_FALSE(m.has_value());
  CHECK(m.error() == "/nonexistent/model.cao: cannot open (no such file)");
}

TEST_CASE("syntax errors name file, line and the offending token") {
  CHECK(parse_error("") == "t.cao:1: expected version 'V1', got end of file");
  CHECK(parse_error("\n\nV3\n") == "t.cao:3: expected version 'V1', got 'V3'");
  CHECK(parse_error("8\n") == "t.cao:1: expected version 'V1', got '8'");
  CHECK(parse_error("V1\nabc\n") == "t.cao:2: expected number of points, got 'abc'");
  CHECK(parse_error("V1\n2.5\n") == "t.cao:2: expected number of points, got '2.5'");
  CHECK(parse_error("V1\n1\n0 0\n# end\n") ==
        "t.cao:4: expected coordinate Z of point 0 (a finite number), got end of file");
  CHECK(parse_error("V1\n1\n0 0 0\n0\n0\n0\n0\n0\nextra\n") == "t.cao:9: expected end of file, got 'extra'");
  CHECK(parse_error("V1\n1\n0 0 \x01\n") == "t.cao:3: expected coordinate Z of point 0 (a finite number), got '\\x01'");
  // Points spread over lines: the message names the line of the bad token.
  CHECK(parse_error("V1\n2\n0 0\n0 1\n0\nzero 0\n") ==
        "t.cao:6: expected coordinate Z of point 1 (a finite number), got 'zero'");
}

TEST_CASE("negative, absurd and overflowing counts are errors, without allocating for them") {
  CHECK(parse_error("V1\n-1\n") == "t.cao:2: number of points -1 out of range (0 to 10000000)");
  CHECK(parse_error("V1\n10000001\n") == "t.cao:2: number of points 10000001 out of range (0 to 10000000)");
  CHECK(parse_error("V1\n99999999999999999999999\n") ==
        "t.cao:2: number of points '99999999999999999999999' out of range");
  CHECK(parse_error("V1\n10000000\n0 0 0\n") ==
        "t.cao:3: expected coordinate X of point 1 (a finite number), got end of file");
  CHECK(parse_error("V1\n0\n-5\n") == "t.cao:3: number of lines -5 out of range (0 to 10000000)");
  CHECK(parse_error("V1\n0\n0\n0\n0\n0\n-2\n") == "t.cao:7: number of circles -2 out of range (0 to 10000000)");
}

TEST_CASE("non-finite numbers are errors") {
  for (const char* bad : {"nan", "inf", "-inf", "1e999", "NaN", "infinity"}) {
    CHECK(parse_error(std::string("V1\n1\n0 ") + bad + " 0\n" + kTail) ==
          std::string("t.cao:3: expected coordinate Y of point 0 (a finite number), got '") + bad + "'");
  }
  CHECK(parse_error("V1\n2\n0 0 0\n1 0 0\n0\n0\n0\n1\n0 1 nan\n") ==
        "t.cao:9: expected radius (a finite number), got 'nan'");
}

TEST_CASE("indices out of range are errors naming the index and the count") {
  const std::string points = "V1\n3\n0 0 0\n1 0 0\n0 1 0\n";
  CHECK(parse_error(points + "1\n0 12\n") == "t.cao:7: point index 12 out of range (3 points)");
  CHECK(parse_error(points + "1\n-1 2\n") == "t.cao:7: point index -1 out of range (3 points)");
  CHECK(parse_error(points + "0\n0\n1\n3 0 1\n3\n") == "t.cao:10: point index 3 out of range (3 points)");
  CHECK(parse_error(points + "1\n0 1\n1\n3 0 0 2\n") == "t.cao:9: line index 2 out of range (1 lines)");
  CHECK(parse_error(points + "0\n0\n0\n1\n0 9 0.1\n") == "t.cao:10: point index 9 out of range (3 points)");
  CHECK(parse_error(points + "0\n0\n0\n0\n1\n0.1 0 1 3\n") == "t.cao:11: point index 3 out of range (3 points)");
}

TEST_CASE("degenerate items are errors: short faces, equal end points, radius <= 0, collinear circles") {
  const std::string points = "V1\n3\n0 0 0\n1 0 0\n0 1 0\n";
  CHECK(parse_error(points + "0\n0\n1\n2 0 1\n") == "t.cao:9: face has 2 points, needs 3 to 10000000");
  CHECK(parse_error(points + "0\n0\n1\n-3 0 1\n") == "t.cao:9: face has -3 points, needs 3 to 10000000");
  CHECK(parse_error(points + "1\n0 1\n1\n1 0\n") == "t.cao:9: face has 1 lines, needs 3 to 10000000");
  CHECK(parse_error(points + "1\n2 2\n") == "t.cao:7: line has equal end points (2 2)");
  CHECK(parse_error("V1\n2\n0 0 0\n0 0 0\n1\n0 1\n") == "t.cao:6: line has equal end points (0 1)");
  CHECK(parse_error(points + "0\n0\n1\n3 0 1\n1\n") == "t.cao:10: face has point 1 twice in a row");
  CHECK(parse_error(points + "0\n0\n1\n4 0 1 2 0\n") == "t.cao:9: face ends on its first point 0 (do not repeat it)");
  CHECK(parse_error(points + "0\n0\n0\n1\n0 1 0\n") == "t.cao:10: radius must be > 0, got '0'");
  CHECK(parse_error(points + "0\n0\n0\n1\n0 0 0.1\n") == "t.cao:10: cylinder axis points are equal");
  CHECK(parse_error(points + "0\n0\n0\n0\n1\n-0.1 0 1 2\n") == "t.cao:11: radius must be > 0, got '-0.1'");
  CHECK(parse_error("V1\n3\n0 0 0\n1 0 0\n2 0 0\n0\n0\n0\n0\n1\n0.1 0 1 2\n") ==
        "t.cao:11: circle's plane points are collinear with its centre");
}

TEST_CASE("faces from lines that do not form a closed loop are errors") {
  const std::string square = "V1\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4\n0 1\n1 2\n2 3\n3 0\n";
  CHECK(parse_ok(square + "1\n4 0 1 2 3\n0\n").faces[0].vertices == std::vector<int>{0, 1, 2, 3});
  CHECK(parse_ok(square + "1\n4 3 2 1 0\n0\n").faces[0].vertices == std::vector<int>{0, 3, 2, 1});
  CHECK(parse_error(square + "1\n4 0 2 1 3\n") ==
        "t.cao:13: face: line 2 does not continue from line 0 (lines must form a closed loop)");
  CHECK(parse_error(square + "1\n3 0 1 2\n") ==
        "t.cao:13: face: its lines do not close (line 2 does not end where line 0 starts)");
  CHECK(parse_error(square + "1\n3 0 0 1\n") == "t.cao:13: face: line 0 has the same end points as line 0");
}

TEST_CASE("degenerate faces and duplicate edges are warnings with file:line, not errors") {
  const std::string points = "V1\n4\n0 0 0\n1 0 0\n2 0 0\n0 1 0\n";
  const CadModel flat = parse_ok(points + "0\n0\n1\n3 0 1 2\n0\n0\n");
  CHECK(has_warning(flat, "t.cao:10: face 0: is degenerate (zero area)"));
  CHECK(flat.faces[0].normal_obj == Eigen::Vector3d::Zero());
  CHECK(flat.faces[0].triangles.empty());
  const CadModel twice = parse_ok(points + "0\n0\n2\n3 0 1 3\n3 0 1 3\n0\n0\n");
  CHECK(has_warning(twice, "t.cao:11: face 1: edge 0-1 runs the same way as in face 0"));
  const CadModel lines = parse_ok(points + "2\n0 3\n3 0\n0\n0\n0\n0\n");
  CHECK(has_warning(lines, "t.cao:9: line 1: duplicate line 3-0"));
  CHECK(lines.edges.size() == 1);
  const CadModel fin = parse_ok("V1\n5\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n0\n0\n3\n3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  CHECK(fin.edges[0].extra_faces == 1);
  CHECK_FALSE(fin.closed);
  CHECK(has_warning(fin, "t.cao:13: face 2: edge 0-1 is shared by more than two faces"));
}

TEST_CASE("build_model checks models built in memory") {
  RawModel raw;
  raw.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  raw.face_loops = {{0, 1, 5}};
  CHECK(build_model(raw, "mem").error() == "mem: face 0: point index 5 out of range (3 points)");
  raw.face_loops = {{0, 1}};
  CHECK(build_model(raw, "mem").error() == "mem: face 0: has 2 vertices, needs at least 3");
  raw.face_loops = {{0, 1, 1}};
  CHECK(build_model(raw, "mem").error() ==
        "mem: face 0: side 1 has equal end points (point 1 twice in a row)");
  raw.face_loops = {{0, 1, 2}};
  raw.free_lines = {{2, 2}};
  CHECK(build_model(raw, "mem").error() == "mem: line 0: has equal end points (2 2)");
  raw.free_lines.clear();
  raw.circles = {ModelCircle{{0, 0, 0}, {0, 0, 1}, 0.0}};
  CHECK(build_model(raw, "mem").error() == "mem: circle 0: radius must be > 0");
  raw.circles.clear();
  raw.vertices[2].y() = std::nan("");
  CHECK(build_model(raw, "mem").error() == "mem: point 2 is not finite");
  raw.vertices[2].y() = 1;
  auto m = build_model(raw, "mem");
  REQUIRE(m.has_value());
  CHECK(m->faces[0].normal_obj.isApprox(Eigen::Vector3d(0, 0, 1)));
  CHECK_FALSE(m->closed);  // an open triangle
}

TEST_CASE("parallel pairs include collinear edges and skip edges more than 1 degree apart") {
  RawModel raw;
  const double tilt = std::tan(0.9 * std::numbers::pi / 180);  // 0.9 degrees: parallel
  const double skew = std::tan(1.1 * std::numbers::pi / 180);  // 1.1 degrees: not parallel
  raw.vertices = {{0, 0, 0},   {1, 0, 0},           {2, 0, 0}, {3, 0, 0},
                  {0, 0.5, 0}, {1, 0.5 + tilt, 0}, {0, 0, 2}, {1, 0, 2 + skew}};
  raw.free_lines = {{0, 1}, {2, 3}, {4, 5}, {6, 7}};
  auto m = build_model(raw);
  REQUIRE(m.has_value());
  REQUIRE(m->parallel_pairs.size() == 3);
  CHECK(m->parallel_pairs[0].edge_a == 0);
  CHECK(m->parallel_pairs[0].edge_b == 1);
  CHECK(m->parallel_pairs[0].distance_m == Approx(0).margin(1e-15));  // collinear
  CHECK(m->parallel_pairs[1].edge_a == 0);
  CHECK(m->parallel_pairs[1].edge_b == 2);
  CHECK(m->parallel_pairs[1].distance_m == Approx(0.5 + tilt / 2).epsilon(1e-3));
  CHECK(m->parallel_pairs[2].edge_a == 1);
  CHECK(m->parallel_pairs[2].edge_b == 2);
}

TEST_CASE("a comb-shaped face (many reflex corners) triangulates into n - 2 CCW triangles") {
  RawModel raw;
  // Comb: teeth along x, seen from +z, CCW.
  std::vector<Eigen::Vector3d>& v = raw.vertices;
  v.push_back({0, 0, 0});
  const int teeth = 20;
  v.push_back({2.0 * teeth, 0, 0});
  for (int i = teeth - 1; i >= 0; --i) {
    v.push_back({2.0 * i + 2, 3, 0});
    v.push_back({2.0 * i + 1, 3, 0});
    v.push_back({2.0 * i + 1, 1, 0});
    v.push_back({2.0 * i, 1, 0});
  }
  v.pop_back();  // the last inner corner is (0, 1): drop it, the face closes at (0, 0)
  std::vector<int> loop(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) loop[i] = static_cast<int>(i);
  raw.face_loops = {loop};
  auto m = build_model(raw);
  REQUIRE(m.has_value());
  CHECK(m->warnings.empty());
  CadModel faces_only = *m;
  faces_only.edges.clear();  // into_face points to the centroid only on convex faces
  check_geometry(faces_only);
}

TEST_CASE("to_cao writes a model that reads back the same") {
  for (const std::string& file : {kData + "cube.cao", kData + "l_shape.cao", kData + "cube_from_lines.cao",
                                  kData + "wire_and_round.cao", kData + "include_main.cao",
                                  std::string(EPICHEAD_SHARED_DATA) + "/teabox/model.cao"}) {
    INFO(file);
    const CadModel a = load_ok(file);
    const std::string text = to_cao(a);
    auto b = parse_cao(text, "written.cao");
    INFO(text);
    REQUIRE(b.has_value());
    check_same_model(a, *b);
  }
}

TEST_CASE("to_cao adds points for circles and cylinders built in memory") {
  RawModel raw;
  raw.vertices = {{0, 0, 0}, {1, 0, 0}};
  raw.free_lines = {{0, 1}};
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 3).normalized();
  raw.circles = {ModelCircle{{0.5, 0.5, 0.5}, n, 0.25}};
  raw.cylinders = {{{2, 0, 0}, {2, 0, 1}, 0.1}};
  auto a = build_model(raw);
  REQUIRE(a.has_value());
  auto b = parse_cao(to_cao(*a), "written.cao");
  REQUIRE(b.has_value());
  CHECK(b->vertices.size() == 2 + 3 + 2);
  REQUIRE(b->circles.size() == 1);
  CHECK((b->circles[0].normal_obj - n).norm() < 1e-12);
  CHECK(b->circles[0].centre_obj == a->circles[0].centre_obj);
  CHECK(b->circles[0].radius_m == 0.25);
  REQUIRE(b->cylinders.size() == 1);
  CHECK(b->cylinders[0].axis_b_obj == Eigen::Vector3d(2, 0, 1));
  CHECK(b->edges.size() == 1);
}
