// The built-in scenes' tracked objects as wire-frame models (vision::CadModel), built from the
// dimensions their rendered meshes share (scene_shapes.h).
#include <cmath>
#include <numbers>
#include <string>

#include "epichead/sim/scene_library.h"
#include "scene_shapes.h"

namespace epichead::sim {
namespace {

using Eigen::Vector3d;
using vision::RawModel;
using namespace scenes;

// An axis-aligned box as 8 points and 6 faces (CCW from outside). Returns its first face index.
int add_box_model(RawModel& raw, const Vector3d& lo, const Vector3d& hi) {
  const int first = static_cast<int>(raw.vertices.size());
  for (int i = 0; i < 8; ++i)
    raw.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  auto v = [&](int sx, int sy, int sz) { return first + (sx ? 1 : 0) + (sy ? 2 : 0) + (sz ? 4 : 0); };
  const int face = static_cast<int>(raw.face_loops.size());
  raw.face_loops.push_back({v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)});  // +x
  raw.face_loops.push_back({v(0, 1, 0), v(0, 0, 0), v(0, 0, 1), v(0, 1, 1)});  // -x
  raw.face_loops.push_back({v(1, 1, 0), v(0, 1, 0), v(0, 1, 1), v(1, 1, 1)});  // +y
  raw.face_loops.push_back({v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)});  // -y
  raw.face_loops.push_back({v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)});  // +z
  raw.face_loops.push_back({v(0, 1, 0), v(1, 1, 0), v(1, 0, 0), v(0, 0, 0)});  // -z
  return face;
}

int add_quad_model(RawModel& raw, const Vector3d& a, const Vector3d& b, const Vector3d& c, const Vector3d& d) {
  const int first = static_cast<int>(raw.vertices.size());
  raw.vertices.insert(raw.vertices.end(), {a, b, c, d});
  raw.face_loops.push_back({first, first + 1, first + 2, first + 3});
  return static_cast<int>(raw.face_loops.size()) - 1;
}

// Rings of `facets` vertices at the given (radius, height) profile points and the quads between
// consecutive rings (CCW from outside): a body of revolution about z as ViSP users model one.
void add_revolution_model(RawModel& raw, const std::vector<Eigen::Vector2d>& profile, int facets) {
  const int first = static_cast<int>(raw.vertices.size());
  for (const Eigen::Vector2d& rz : profile)
    for (int i = 0; i < facets; ++i) {
      const double a = 2 * std::numbers::pi * i / facets;
      raw.vertices.emplace_back(rz.x() * std::cos(a), rz.x() * std::sin(a), rz.y());
    }
  for (std::size_t ring = 0; ring + 1 < profile.size(); ++ring)
    for (int i = 0; i < facets; ++i) {
      const int lo = first + static_cast<int>(ring) * facets, hi = lo + facets;
      const int j = (i + 1) % facets;
      raw.face_loops.push_back({lo + i, lo + j, hi + j, hi + i});
    }
}

}  // namespace

std::expected<vision::CadModel, std::string> make_scene_model(std::string_view name) {
  RawModel raw;
  if (name == "mockup_walk") {
    for (const auto& p : kMockupParts) add_box_model(raw, p.lo, p.hi);
  } else if (name == "lampshade") {
    for (int ring = 0; ring < 2; ++ring)
      for (int i = 0; i < kShadeFacets; ++i) {
        const double a = 2 * std::numbers::pi * i / kShadeFacets;
        const double r = ring == 0 ? kShadeBottomRadius : kShadeTopRadius;
        raw.vertices.emplace_back(r * std::cos(a), r * std::sin(a), ring == 0 ? 0.0 : kShadeHeight);
      }
    for (int i = 0; i < kShadeFacets; ++i) {
      const int j = (i + 1) % kShadeFacets;
      raw.face_loops.push_back({i, j, kShadeFacets + j, kShadeFacets + i});
    }
    // The rims, each facing out of its opening.
    raw.circles.push_back({Vector3d::Zero(), -Vector3d::UnitZ(), kShadeBottomRadius});
    raw.circles.push_back({Vector3d(0, 0, kShadeHeight), Vector3d::UnitZ(), kShadeTopRadius});
  } else if (name == "box_clutter") {
    add_box_model(raw, kPackageLo, kPackageHi);
  } else if (name == "can") {
    add_revolution_model(raw, {{kCanRadius, 0.0}, {kCanRadius, kCanHeight}}, kCanFacets);
    raw.circles.push_back({Vector3d::Zero(), -Vector3d::UnitZ(), kCanRadius});
    raw.circles.push_back({Vector3d(0, 0, kCanHeight), Vector3d::UnitZ(), kCanRadius});
  } else if (name == "bowl") {
    std::vector<Eigen::Vector2d> profile;
    for (int ring = 0; ring <= kBowlRings; ++ring) profile.push_back(bowl_profile(static_cast<double>(ring) / kBowlRings));
    add_revolution_model(raw, profile, kBowlFacets);
    // The open top: its rim, facing out of the opening.
    raw.circles.push_back({Vector3d(0, 0, profile.back().y()), Vector3d::UnitZ(), profile.back().x()});
  } else if (name == "office_pan") {
    add_quad_model(raw, {0, 0, 0}, {0, -kRoomY, 0}, {kRoomX, -kRoomY, 0}, {kRoomX, 0, 0});       // floor
    add_quad_model(raw, {0, 0, 0}, {kRoomX, 0, 0}, {kRoomX, 0, kRoomH}, {0, 0, kRoomH});         // back wall
    add_quad_model(raw, {0, -kRoomY, 0}, {0, 0, 0}, {0, 0, kRoomH}, {0, -kRoomY, kRoomH});       // left wall
    for (const auto& b : kOfficeBoxes) add_box_model(raw, b.lo, b.hi);
  } else {
    std::string known;
    for (const auto& n : scene_names()) {
      if (!known.empty()) known += ", ";
      known += n;
    }
    return std::unexpected("unknown scene '" + std::string(name) + "' (known: " + known + ")");
  }
  return vision::build_model(raw, std::string(name));
}

}  // namespace epichead::sim
