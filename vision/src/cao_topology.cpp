// Topology of a CAD model: face normals and triangulations, edges with their faces, junctions
// and parallel edge pairs, from vertices and vertex loops (build_model); the points that stand
// for its outline (outline_points).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "cao_build.h"

namespace epichead::vision {
namespace {

// Parallel edges: directions within this angle.
const double kParallelCos = std::cos(1.0 * std::numbers::pi / 180.0);
// More parallel pairs than this would only come from a pathological model; the list is cut
// there (with a warning) so that loading stays linear in the model size.
constexpr std::size_t kMaxParallelPairs = 1'000'000;
// Work budget (point-in-triangle tests) of ear clipping for a whole model: ear clipping is
// quadratic, cubic on adversarial polygons; past the budget the rest of a face is fanned.
constexpr long long kEarClipBudget = 20'000'000;
// A face whose doubled area is below this fraction of its squared perimeter has no plane.
constexpr double kDegenerateRatio = 1e-9;
// Vertices farther than this fraction of the perimeter from the face plane: not planar.
constexpr double kPlanarityRatio = 1e-4;
// How errors state the bound on coordinates and radii (cao_model.h).
const std::string kExtentText = "the 1e6 m a physical model can have";

std::uint64_t edge_key(int a, int b) {
  const auto lo = static_cast<std::uint32_t>(std::min(a, b));
  const auto hi = static_cast<std::uint32_t>(std::max(a, b));
  return (std::uint64_t{lo} << 32) | hi;
}

class Namer {
 public:
  Namer(const std::string& name, const detail::RawSources* where) : name_(name), where_(where) {}
  std::string face(std::size_t i) const { return at(where_ ? &where_->faces : nullptr, i, "face"); }
  std::string line(std::size_t i) const { return at(where_ ? &where_->lines : nullptr, i, "line"); }
  std::string circle(std::size_t i) const { return at(where_ ? &where_->circles : nullptr, i, "circle"); }
  std::string cylinder(std::size_t i) const {
    return at(where_ ? &where_->cylinders : nullptr, i, "cylinder");
  }
  const std::string& model() const { return name_; }

 private:
  std::string at(const std::vector<std::string>* list, std::size_t i, const char* kind) const {
    const std::string& prefix = (list && i < list->size()) ? (*list)[i] : name_;
    return prefix + ": " + kind + " " + std::to_string(i);
  }
  const std::string& name_;
  const detail::RawSources* where_;
};

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

std::unexpected<std::string> index_error(const std::string& who, long long index, std::size_t count) {
  return std::unexpected(who + ": point index " + std::to_string(index) + " out of range (" +
                         std::to_string(count) + " points)");
}

std::expected<void, std::string> validate(const RawModel& raw, const Namer& namer) {
  const std::size_t nv = raw.vertices.size();
  // Within the physical bound, every difference, length and distance below stays finite.
  const auto beyond = [](const Eigen::Vector3d& v) { return !(v.cwiseAbs().maxCoeff() <= kMaxModelExtentM); };
  for (std::size_t i = 0; i < nv; ++i) {
    if (!finite(raw.vertices[i])) {
      return std::unexpected(namer.model() + ": point " + std::to_string(i) + " is not finite");
    }
    if (beyond(raw.vertices[i])) {
      return std::unexpected(namer.model() + ": point " + std::to_string(i) + " is beyond " + kExtentText);
    }
  }
  auto in_range = [nv](int i) { return i >= 0 && static_cast<std::size_t>(i) < nv; };
  for (std::size_t f = 0; f < raw.face_loops.size(); ++f) {
    const auto& loop = raw.face_loops[f];
    if (loop.size() < 3) {
      return std::unexpected(namer.face(f) + ": has " + std::to_string(loop.size()) +
                             " vertices, needs at least 3");
    }
    for (int v : loop) {
      if (!in_range(v)) return index_error(namer.face(f), v, nv);
    }
    for (std::size_t i = 0; i < loop.size(); ++i) {
      if (loop[i] == loop[(i + 1) % loop.size()]) {
        return std::unexpected(namer.face(f) + ": side " + std::to_string(i) +
                               " has equal end points (point " + std::to_string(loop[i]) + " twice in a row)");
      }
    }
  }
  for (std::size_t l = 0; l < raw.free_lines.size(); ++l) {
    const auto& line = raw.free_lines[l];
    for (int v : line) {
      if (!in_range(v)) return index_error(namer.line(l), v, nv);
    }
    if (line[0] == line[1] || raw.vertices[line[0]] == raw.vertices[line[1]]) {
      return std::unexpected(namer.line(l) + ": has equal end points (" + std::to_string(line[0]) + " " +
                             std::to_string(line[1]) + ")");
    }
  }
  for (std::size_t c = 0; c < raw.circles.size(); ++c) {
    const ModelCircle& circle = raw.circles[c];
    if (!finite(circle.centre_obj) || !finite(circle.normal_obj) || !std::isfinite(circle.radius_m)) {
      return std::unexpected(namer.circle(c) + ": is not finite");
    }
    if (!(circle.radius_m > 0)) return std::unexpected(namer.circle(c) + ": radius must be > 0");
    if (beyond(circle.centre_obj) || circle.radius_m > kMaxModelExtentM)
      return std::unexpected(namer.circle(c) + ": centre or radius is beyond " + kExtentText);
    if (!(circle.normal_obj.norm() > 0)) return std::unexpected(namer.circle(c) + ": normal is zero");
  }
  for (std::size_t c = 0; c < raw.cylinders.size(); ++c) {
    const ModelCylinder& cyl = raw.cylinders[c];
    if (!finite(cyl.axis_a_obj) || !finite(cyl.axis_b_obj) || !std::isfinite(cyl.radius_m)) {
      return std::unexpected(namer.cylinder(c) + ": is not finite");
    }
    if (!(cyl.radius_m > 0)) return std::unexpected(namer.cylinder(c) + ": radius must be > 0");
    if (beyond(cyl.axis_a_obj) || beyond(cyl.axis_b_obj) || cyl.radius_m > kMaxModelExtentM)
      return std::unexpected(namer.cylinder(c) + ": axis or radius is beyond " + kExtentText);
    if (cyl.axis_a_obj == cyl.axis_b_obj) {
      return std::unexpected(namer.cylinder(c) + ": axis end points are equal");
    }
  }
  return {};
}

double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

// p inside or on the CCW triangle (a, b, c).
bool in_triangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                 const Eigen::Vector2d& c) {
  return cross2(b - a, p - a) >= 0 && cross2(c - b, p - b) >= 0 && cross2(a - c, p - c) >= 0;
}

// Ear clipping of a simple polygon given CCW in 2D (`pts[i]` is the position of loop[i]).
// Only reflex vertices can lie inside an ear, so only they are tested: near-linear for the
// mostly convex faces of CAD models. Emits loop.size() - 2 triangles whatever the input;
// returns false when the polygon was not simple (no ear left) or `budget` (point tests, shared
// by all faces of a model) ran out and the rest was fanned, so the result is approximate.
bool ear_clip(const std::vector<Eigen::Vector2d>& pts, const std::vector<int>& loop,
              std::vector<std::array<int, 3>>& out, long long& budget) {
  const int n = static_cast<int>(loop.size());
  std::vector<int> prev(n), next(n);
  for (int i = 0; i < n; ++i) {
    prev[i] = (i + n - 1) % n;
    next[i] = (i + 1) % n;
  }
  auto convex = [&](int i) { return cross2(pts[i] - pts[prev[i]], pts[next[i]] - pts[i]) > 0; };
  std::vector<unsigned char> reflex(n), removed(n, 0);
  std::vector<int> reflex_list;
  for (int i = 0; i < n; ++i) {
    reflex[i] = !convex(i);
    if (reflex[i]) reflex_list.push_back(i);
  }
  std::size_t stale = 0;
  bool exact = true;
  auto is_ear = [&](int p, int i, int q) {
    --budget;
    if (reflex[i]) return false;
    const Eigen::Vector2d &a = pts[p], &b = pts[i], &c = pts[q];
    for (const int j : reflex_list) {
      if (removed[j] || !reflex[j] || j == p || j == q) continue;
      if (--budget < 0) return true;  // out of budget: accept, reported by the return value
      const Eigen::Vector2d& x = pts[j];
      if (x == a || x == b || x == c) continue;  // a repeated vertex touches, it does not intrude
      if (in_triangle(x, a, b, c)) return false;
    }
    return true;
  };
  auto update = [&](int v) {  // v's neighbours changed
    const bool now_reflex = !convex(v);
    if (now_reflex && !reflex[v]) reflex_list.push_back(v);  // only after a forced ear
    if (!now_reflex && reflex[v]) ++stale;
    reflex[v] = now_reflex;
  };
  int remaining = n;
  int i = 0;
  int stalled = 0;
  while (remaining > 3) {
    const int p = prev[i], q = next[i];
    bool clip = budget < 0 || is_ear(p, i, q);  // out of budget: fan the rest
    if (!clip && ++stalled > remaining) {
      clip = true;  // a full turn without an ear: not a simple polygon; force one to finish
      exact = false;
    }
    if (!clip) {
      i = q;
      continue;
    }
    out.push_back({loop[p], loop[i], loop[q]});
    next[p] = q;
    prev[q] = p;
    removed[i] = 1;
    if (reflex[i]) ++stale;
    update(p);
    update(q);
    if (stale > 64 && 2 * stale > reflex_list.size()) {
      std::erase_if(reflex_list, [&](int j) { return removed[j] || !reflex[j]; });
      stale = 0;
    }
    --remaining;
    stalled = 0;
    i = p;  // the neighbours changed: they are the next candidates
  }
  out.push_back({loop[prev[i]], loop[i], loop[next[i]]});
  return exact && budget >= 0;
}

// Newell normal, offset, planarity and triangulation of one face.
void make_face(const std::vector<Eigen::Vector3d>& vertices, const std::vector<int>& loop, ModelFace& face,
               const std::string& who, long long& budget, std::vector<std::string>& warnings) {
  face.vertices = loop;
  const std::size_t n = loop.size();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int v : loop) centroid += vertices[v];
  centroid /= static_cast<double>(n);
  Eigen::Vector3d newell = Eigen::Vector3d::Zero();
  double perimeter = 0;
  bool zero_side = false;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = vertices[loop[i]] - centroid;
    const Eigen::Vector3d b = vertices[loop[(i + 1) % n]] - centroid;
    newell += a.cross(b);
    const double side = (b - a).norm();
    zero_side = zero_side || side == 0;
    perimeter += side;
  }
  if (zero_side) warnings.push_back(who + ": has a side of zero length");
  {
    std::vector<int> sorted = loop;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
      warnings.push_back(who + ": visits a point twice (not a simple polygon)");
    }
  }
  const double area2 = newell.norm();
  if (!(area2 > kDegenerateRatio * perimeter * perimeter)) {
    // No plane: the face keeps its place in the topology but has no normal and hides nothing.
    warnings.push_back(who + ": is degenerate (zero area); it has no normal and no triangles");
    face.normal_obj = Eigen::Vector3d::Zero();
    face.offset_m = 0;
    return;
  }
  face.normal_obj = newell / area2;
  face.offset_m = face.normal_obj.dot(centroid);
  double off_plane = 0;
  for (int v : loop) off_plane = std::max(off_plane, std::abs(face.normal_obj.dot(vertices[v]) - face.offset_m));
  if (off_plane > kPlanarityRatio * perimeter) {
    warnings.push_back(who + ": is not planar (a point is " + std::to_string(off_plane) + " m off its plane)");
  }
  if (n == 3) {
    face.triangles.push_back({loop[0], loop[1], loop[2]});
    return;
  }
  // Project onto the plane of the dominant normal axis, mirrored if needed to keep it CCW.
  int k = 0;
  face.normal_obj.cwiseAbs().maxCoeff(&k);
  const int ia = (k + 1) % 3, ib = (k + 2) % 3;
  const double flip = face.normal_obj[k] < 0 ? -1.0 : 1.0;
  std::vector<Eigen::Vector2d> pts(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d p = vertices[loop[i]] - centroid;
    pts[i] = {p[ia], flip * p[ib]};
  }
  if (!ear_clip(pts, loop, face.triangles, budget)) {
    warnings.push_back(who + ": is not a simple polygon; its triangulation is approximate");
  }
}

// Edges from face loops (in face order), then free lines that are not face edges.
void make_edges(const RawModel& raw, CadModel& model, const Namer& namer) {
  std::unordered_map<std::uint64_t, int> index;
  std::vector<unsigned char> from_line;       // per edge: declared as a free line
  std::vector<std::array<int, 2>> first_dir;  // per edge: first face and whether it runs v0->v1
  auto edge_of = [&](int a, int b, bool& created) {
    const auto [it, inserted] = index.try_emplace(edge_key(a, b), static_cast<int>(model.edges.size()));
    created = inserted;
    if (inserted) {
      ModelEdge e;
      e.v0 = a;
      e.v1 = b;
      model.edges.push_back(e);
      from_line.push_back(0);
      first_dir.push_back({-1, 0});
    }
    return it->second;
  };
  auto pair_name = [](int a, int b) { return std::to_string(a) + "-" + std::to_string(b); };
  for (std::size_t f = 0; f < model.faces.size(); ++f) {
    const ModelFace& face = model.faces[f];
    const std::size_t n = face.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
      const int a = face.vertices[i], b = face.vertices[(i + 1) % n];
      bool created = false;
      const int e = edge_of(a, b, created);
      ModelEdge& edge = model.edges[e];
      const bool forward = edge.v0 == a;
      if (!created && first_dir[e][0] >= 0 && first_dir[e][1] == forward) {
        model.warnings.push_back(namer.face(f) + ": edge " + pair_name(a, b) + " runs the same way as in face " +
                                 std::to_string(first_dir[e][0]) +
                                 " (duplicate edge: a face is not CCW from outside, or is repeated)");
      }
      if (first_dir[e][0] < 0) first_dir[e] = {static_cast<int>(f), forward};
      Eigen::Vector3d into = face.normal_obj.cross(model.vertices[b] - model.vertices[a]);
      const double len = into.norm();
      into = len > 0 ? Eigen::Vector3d(into / len) : Eigen::Vector3d::Zero();
      if (edge.faces[0] < 0) {
        edge.faces[0] = static_cast<int>(f);
        edge.into_face[0] = into;
      } else if (edge.faces[1] < 0) {
        edge.faces[1] = static_cast<int>(f);
        edge.into_face[1] = into;
      } else {
        if (edge.extra_faces == 0) {
          model.warnings.push_back(namer.face(f) + ": edge " + pair_name(a, b) +
                                   " is shared by more than two faces (non-manifold)");
        }
        ++edge.extra_faces;
      }
    }
  }
  for (std::size_t l = 0; l < raw.free_lines.size(); ++l) {
    const auto [a, b] = raw.free_lines[l];
    bool created = false;
    const int e = edge_of(a, b, created);
    if (!created && from_line[e]) {
      model.warnings.push_back(namer.line(l) + ": duplicate line " + pair_name(a, b));
    }
    from_line[e] = 1;  // a line on a face edge merges into it
  }
}

// Junctions: vertices with two or more edges, edge lists in edge order (counting sort, no
// per-vertex containers: the vertex count may be large).
void make_junctions(CadModel& model) {
  const std::size_t nv = model.vertices.size();
  std::vector<int> start(nv + 1, 0);
  for (const ModelEdge& e : model.edges) {
    ++start[e.v0 + 1];
    ++start[e.v1 + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<int> fill(start.begin(), start.end() - 1);
  std::vector<int> incident(static_cast<std::size_t>(start[nv]));
  for (std::size_t e = 0; e < model.edges.size(); ++e) {
    incident[fill[model.edges[e].v0]++] = static_cast<int>(e);
    incident[fill[model.edges[e].v1]++] = static_cast<int>(e);
  }
  for (std::size_t v = 0; v < nv; ++v) {
    if (start[v + 1] - start[v] < 2) continue;
    ModelJunction j;
    j.vertex = static_cast<int>(v);
    j.edges.assign(incident.begin() + start[v], incident.begin() + start[v + 1]);
    model.junctions.push_back(std::move(j));
  }
}

double point_line_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  const Eigen::Vector3d d = p - origin;
  return (d - d.dot(dir) * dir).norm();
}

// Parallel pairs by hashing unit directions into a grid whose cells are wider than the 1 degree
// chord, so only neighbouring cells of d and -d hold candidates: linear in the edges plus the
// pairs found, rather than quadratic in the edges.
void make_parallel_pairs(CadModel& model) {
  constexpr double kCell = 0.02;  // > 2 sin(0.5 deg) = 0.01745
  const std::size_t ne = model.edges.size();
  std::vector<Eigen::Vector3d> dir(ne);
  std::vector<unsigned char> valid(ne, 0);
  for (std::size_t e = 0; e < ne; ++e) {
    const Eigen::Vector3d d = model.vertices[model.edges[e].v1] - model.vertices[model.edges[e].v0];
    const double len = d.norm();
    // build_model bounds the vertices, so len is finite; an edge that is not is skipped all
    // the same rather than cast to a grid cell as NaN.
    if (len > 0 && std::isfinite(len)) {
      dir[e] = d / len;
      valid[e] = dir[e].allFinite() ? 1 : 0;
    }
  }
  // dir is a unit vector: its cells are -50..50, well inside int (clamped all the same).
  auto cell_of = [](const Eigen::Vector3d& d) {
    const auto cell = [](double x) { return static_cast<int>(std::clamp(std::floor(x / kCell), -100.0, 100.0)); };
    return Eigen::Vector3i(cell(d.x()), cell(d.y()), cell(d.z()));
  };
  auto key_of = [](const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x() + 1000) << 40) | (static_cast<std::uint64_t>(c.y() + 1000) << 20) |
           static_cast<std::uint64_t>(c.z() + 1000);
  };
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  bool capped = false;
  for (std::size_t e = 0; e < ne && !capped; ++e) {
    if (!valid[e]) continue;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3i c = cell_of(sign * dir[e]);
      for (int dx = -1; dx <= 1; ++dx) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dz = -1; dz <= 1; ++dz) {
            const auto it = grid.find(key_of(c + Eigen::Vector3i(dx, dy, dz)));
            if (it == grid.end()) continue;
            for (const int other : it->second) {
              if (std::abs(dir[e].dot(dir[other])) < kParallelCos) continue;
              const ModelEdge &a = model.edges[other], &b = model.edges[e];
              const Eigen::Vector3d mid_a = 0.5 * (model.vertices[a.v0] + model.vertices[a.v1]);
              const Eigen::Vector3d mid_b = 0.5 * (model.vertices[b.v0] + model.vertices[b.v1]);
              // Symmetric: the lines are parallel only up to 1 degree.
              const double distance = 0.5 * (point_line_distance(mid_b, model.vertices[a.v0], dir[other]) +
                                             point_line_distance(mid_a, model.vertices[b.v0], dir[e]));
              if (!std::isfinite(distance)) continue;
              model.parallel_pairs.push_back({other, static_cast<int>(e), distance});
            }
          }
        }
      }
    }
    grid[key_of(cell_of(dir[e]))].push_back(static_cast<int>(e));
    capped = model.parallel_pairs.size() >= kMaxParallelPairs;
  }
  if (capped) {
    model.warnings.push_back("more than " + std::to_string(kMaxParallelPairs) +
                             " parallel edge pairs; the list is cut short");
  }
  std::sort(model.parallel_pairs.begin(), model.parallel_pairs.end(), [](const ParallelPair& x, const ParallelPair& y) {
    return x.edge_a != y.edge_a ? x.edge_a < y.edge_a : x.edge_b < y.edge_b;
  });
}

}  // namespace

namespace detail {

std::expected<CadModel, std::string> build_model_located(const RawModel& raw, const std::string& name,
                                                         const RawSources* where) {
  const Namer namer(name, where);
  if (auto ok = validate(raw, namer); !ok) return std::unexpected(ok.error());
  CadModel model;
  model.vertices = raw.vertices;
  model.cylinders = raw.cylinders;
  model.circles = raw.circles;
  for (ModelCircle& c : model.circles) c.normal_obj.normalize();
  model.faces.resize(raw.face_loops.size());
  long long budget = kEarClipBudget;
  for (std::size_t f = 0; f < raw.face_loops.size(); ++f) {
    make_face(model.vertices, raw.face_loops[f], model.faces[f], namer.face(f), budget, model.warnings);
  }
  make_edges(raw, model, namer);
  make_junctions(model);
  make_parallel_pairs(model);
  model.closed = !model.faces.empty() && std::all_of(model.edges.begin(), model.edges.end(), [](const ModelEdge& e) {
    return e.face_count() == 2 && e.extra_faces == 0;
  });
  return model;
}

}  // namespace detail

std::expected<CadModel, std::string> build_model(const RawModel& raw, const std::string& name) {
  return detail::build_model_located(raw, name, nullptr);
}

bool on_circle(const ModelCircle& circle, const Eigen::Vector3d& p_obj) {
  const Eigen::Vector3d n = circle.normal_obj.normalized();
  const Eigen::Vector3d d = p_obj - circle.centre_obj;
  const double tol = 1e-3 * circle.radius_m + 1e-6;
  return std::abs(d.dot(n)) <= tol && std::abs((d - d.dot(n) * n).norm() - circle.radius_m) <= tol;
}

std::vector<Eigen::Vector3d> outline_points(const CadModel& model, std::size_t max_vertices) {
  std::vector<Eigen::Vector3d> points;
  const std::size_t step = std::max<std::size_t>(1, model.vertices.size() / std::max<std::size_t>(1, max_vertices));
  for (std::size_t i = 0; i < model.vertices.size(); i += step) points.push_back(model.vertices[i]);
  for (const auto& c : model.circles) {
    const Eigen::Vector3d u = c.normal_obj.unitOrthogonal(), v = c.normal_obj.normalized().cross(u);
    for (int k = 0; k < 8; ++k)
      points.push_back(c.centre_obj + c.radius_m * (std::cos(k * std::numbers::pi / 4) * u + std::sin(k * std::numbers::pi / 4) * v));
  }
  return points;
}

}  // namespace epichead::vision
