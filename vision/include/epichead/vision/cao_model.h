#pragma once
// A wire-frame CAD model read from ViSP's CAO text format (version 1), with the topology the
// tracker needs: edges with the faces that share them, outward face normals, junctions and
// pairs of parallel edges. Units are metres, in the object frame.
#include <array>
#include <expected>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace epichead::vision {

// A planar polygon, vertices counter-clockwise seen from outside.
struct ModelFace {
  std::vector<int> vertices;                 // indices into CadModel::vertices, CCW from outside
  Eigen::Vector3d normal_obj{0, 0, 1};       // outward unit normal (Newell's method); zero for a zero-area face, which has no triangles
  double offset_m = 0;                       // plane: normal_obj . X = offset_m (0 for a degenerate face)
  std::vector<std::array<int, 3>> triangles; // ear-clipped triangulation (vertex indices), for occlusion
};

// An undirected model edge between two vertices (v0 < v1 is not required; v0 != v1 is).
struct ModelEdge {
  int v0 = -1, v1 = -1;
  // Up to two faces sharing the edge (-1 when absent): 0 faces = a free 3D line, 1 = a
  // boundary of an open surface, 2 = a contour or crease of a solid.
  std::array<int, 2> faces{-1, -1};
  // For each face in `faces`: unit vector in the face plane, normal to the edge, pointing into
  // the face (object frame). Used to tell on which side of the projected edge the object is.
  std::array<Eigen::Vector3d, 2> into_face{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  int extra_faces = 0;  // faces beyond two (non-manifold edge); counted, not used
  int face_count() const { return (faces[0] >= 0) + (faces[1] >= 0); }
};

// A circle (rim, hole): centre, unit normal of its plane, radius.
struct ModelCircle {
  Eigen::Vector3d centre_obj = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_obj{0, 0, 1};
  double radius_m = 0;
};

// True when p_obj lies on the circle, within a thousandth of its radius (a vertex of the facets
// that model its rim, written with a few decimals).
bool on_circle(const ModelCircle& circle, const Eigen::Vector3d& p_obj);

// A cylinder given by two points on its axis and a radius; it is tracked by its silhouette.
struct ModelCylinder {
  Eigen::Vector3d axis_a_obj = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis_b_obj = Eigen::Vector3d::Zero();
  double radius_m = 0;
};

// A vertex where two or more edges meet.
struct ModelJunction {
  int vertex = -1;
  std::vector<int> edges;  // indices into CadModel::edges
};

// Two edges whose 3D directions are parallel (within 1 degree).
struct ParallelPair {
  int edge_a = -1, edge_b = -1;
  double distance_m = 0;  // distance between the two (infinite) lines
};

struct CadModel {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<ModelFace> faces;
  std::vector<ModelEdge> edges;
  std::vector<ModelCircle> circles;
  std::vector<ModelCylinder> cylinders;
  std::vector<ModelJunction> junctions;
  std::vector<ParallelPair> parallel_pairs;
  // Every edge shared by exactly two faces: back faces are then always hidden by front faces.
  bool closed = false;
  // Non-fatal findings while loading (degenerate face, duplicate edge, ...), "file:line: what".
  std::vector<std::string> warnings;
};

// Points whose projections stand for the model's outline: every k-th vertex (at most
// `max_vertices` of them) and eight points on each circle. A pose puts the whole model in the
// image when all of them project inside it.
std::vector<Eigen::Vector3d> outline_points(const CadModel& model, std::size_t max_vertices = 64);

// Parses a CAO file (and the files it load()s, relative to the including file, with a
// cycle check). Errors say "file:line: what was expected". Never crashes or hangs on garbage.
std::expected<CadModel, std::string> load_cao(const std::string& path);
// Parses CAO text held in memory; `name` is used in messages and `base_dir` resolves load().
std::expected<CadModel, std::string> parse_cao(const std::string& text, const std::string& name,
                                               const std::string& base_dir = ".");

// No physical model has a coordinate, radius or load() translation beyond this (1000 km):
// larger values are an error, so that every length and distance computed from them is finite.
inline constexpr double kMaxModelExtentM = 1e6;

// Writes a model back as CAO V1 (points, lines for free edges, faces from points, cylinders, circles).
std::string to_cao(const CadModel& model);

// Builds edges, normals, triangulations, junctions, parallel pairs and `closed` from the
// vertices, faces (vertex loops), free lines, circles and cylinders already in the model.
// Exposed so that code that builds models in memory (tests, the simulator) gets the same topology.
struct RawModel {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> face_loops;        // vertex loops, CCW from outside
  std::vector<std::array<int, 2>> free_lines;      // vertex pairs not on any face
  std::vector<ModelCircle> circles;
  std::vector<ModelCylinder> cylinders;
};
std::expected<CadModel, std::string> build_model(const RawModel& raw, const std::string& name = "model");

}  // namespace epichead::vision
