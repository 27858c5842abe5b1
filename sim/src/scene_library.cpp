// The built-in scenes: geometry (model and render meshes), appearance, environment, light.
#include "epichead/sim/scene_library.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "epichead/sim/builtin_asset.h"
#include "scene_photo.h"
#include "texture.h"

namespace epichead::sim {
namespace {

using Eigen::Vector3d;
using vision::RawModel;

// ---- model building -------------------------------------------------------------------------

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

// Lamp shade geometry (object frame: bottom rim centre at the origin, axis +z).
constexpr double kShadeBottomRadius = 0.12, kShadeTopRadius = 0.07, kShadeHeight = 0.16;
constexpr int kShadeFacets = 36;

// Can (object frame: bottom centre at the origin, axis +z): a cylinder modelled, as ViSP users do,
// by its facets and its two rim circles; rendered smooth.
constexpr double kCanRadius = 0.04, kCanHeight = 0.12;
constexpr int kCanFacets = 32;

// Bowl (object frame: bottom centre at the origin, axis +z): the profile's slope angle grows
// linearly along its arc length s, so r(s) and z(s) are closed-form and the render can sample the
// same curve finely. The model's rings are points of that curve; facets of neighbouring rings
// differ by (end - start) / rings = 12 deg, below the 20 deg crease angle, so ring edges are not
// tracked (no image edge there), only the rim circle and the silhouette.
constexpr double kBowlFootRadius = 0.05, kBowlProfileLength = 0.10;
constexpr double kBowlStartSlopeRad = 40.0 * std::numbers::pi / 180, kBowlEndSlopeRad = 88.0 * std::numbers::pi / 180;
constexpr int kBowlRings = 4, kBowlFacets = 32;
// (radius, height) of the bowl profile at fraction u (0 = foot, 1 = rim) of its arc length.
Eigen::Vector2d bowl_profile(double u) {
  const double k = (kBowlEndSlopeRad - kBowlStartSlopeRad) / kBowlProfileLength;
  const double theta = kBowlStartSlopeRad + u * (kBowlEndSlopeRad - kBowlStartSlopeRad);
  return {kBowlFootRadius + (std::sin(theta) - std::sin(kBowlStartSlopeRad)) / k,
          (std::cos(kBowlStartSlopeRad) - std::cos(theta)) / k};
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

// Box of box_clutter: 0.20 x 0.15 x 0.10 m standing on the table, bottom centre at the origin.
const Vector3d kPackageLo(-0.10, -0.075, 0.0), kPackageHi(0.10, 0.075, 0.10);

// mockup_walk parts (object frame: floor at z = 0, viewer on the -y side).
struct MockupPart { const char* name; Vector3d lo, hi; double reflectance; };
const MockupPart kMockupParts[] = {
    {"bulkhead", {-0.50, 0.20, 0.00}, {0.50, 0.22, 0.80}, 0.55},
    {"deck", {-0.50, -0.30, 0.00}, {0.50, 0.20, 0.02}, 0.62},
    {"t_web", {0.195, 0.00, 0.02}, {0.205, 0.20, 0.80}, 0.58},
    {"t_flange", {0.14, -0.012, 0.02}, {0.26, 0.00, 0.80}, 0.60},
    {"bulkhead_stiffener", {-0.50, 0.12, 0.49}, {0.195, 0.20, 0.50}, 0.58},
    {"flat_bar_front", {-0.45, -0.260, 0.02}, {0.45, -0.252, 0.06}, 0.60},
    {"flat_bar_middle", {-0.45, -0.230, 0.02}, {0.45, -0.222, 0.06}, 0.60},
    {"flat_bar_back", {-0.45, -0.200, 0.02}, {0.45, -0.192, 0.06}, 0.60},
};

// office_pan: the room corner at the origin, back wall in the plane y = 0, left wall x = 0.
constexpr double kRoomX = 4.0, kRoomY = 5.0, kRoomH = 2.5;
struct OfficeBox { Vector3d lo, hi; int material; };  // materials: 3 frame, 4 desk top, 5 desk legs
const OfficeBox kOfficeBoxes[] = {
    {{2.13, -0.02, 0.0}, {2.20, 0.0, 2.12}, 3},   // door frame: left jamb
    {{3.10, -0.02, 0.0}, {3.17, 0.0, 2.12}, 3},   // right jamb
    {{2.20, -0.02, 2.05}, {3.10, 0.0, 2.12}, 3},  // head
    {{0.30, -0.75, 0.72}, {1.50, -0.05, 0.75}, 4},  // desk top
    {{0.33, -0.72, 0.0}, {0.37, -0.68, 0.72}, 5},  // legs
    {{1.43, -0.72, 0.0}, {1.47, -0.68, 0.72}, 5},
    {{0.33, -0.12, 0.0}, {0.37, -0.08, 0.72}, 5},
    {{1.43, -0.12, 0.0}, {1.47, -0.08, 0.72}, 5},
};

std::expected<vision::CadModel, std::string> model_of(std::string_view name) {
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

// ---- appearance helpers ---------------------------------------------------------------------

// The seed of one of the object's procedural prints: the built-in one for print_seed 0, else a
// different print for each print_seed (scene variety draws new package prints, labels, plates).
std::uint64_t print(std::uint64_t builtin_seed, std::uint64_t print_seed) {
  return print_seed == 0 ? builtin_seed : builtin_seed ^ (print_seed * 0x9e3779b97f4a7c15ULL);
}

int add_texture(Scene& s, cv::Mat t) {
  s.textures.push_back(std::move(t));
  return static_cast<int>(s.textures.size()) - 1;
}
int add_material(Scene& s, const Material& m) {
  s.materials.push_back(m);
  return static_cast<int>(s.materials.size()) - 1;
}
Material grey(double reflectance) {
  Material m;
  const float r = static_cast<float>(reflectance);
  m.albedo_bgr = {r, r, r};
  return m;
}
Material plain(float b, float g, float r) {
  Material m;
  m.albedo_bgr = {b, g, r};
  return m;
}

// Texture mapping that shows the texture upright on a face seen from outside: origin at the
// face's top-left corner (the loop's last vertex of a quad), u along the top edge, v down the left edge.
void map_texture_on_face(Material& m, const vision::CadModel& model, int face, double px_per_m) {
  const auto& loop = model.faces[static_cast<std::size_t>(face)].vertices;
  const Vector3d& v0 = model.vertices[static_cast<std::size_t>(loop[0])];
  const Vector3d& v2 = model.vertices[static_cast<std::size_t>(loop[2])];
  const Vector3d& v3 = model.vertices[static_cast<std::size_t>(loop[3])];
  m.tex_origin_obj = v3;
  m.tex_u_obj = (v2 - v3).normalized();
  m.tex_v_obj = (v0 - v3).normalized();
  m.tex_px_per_m = px_per_m;
}

// The texture size that covers a quad face exactly at px_per_m.
cv::Size face_texture_size(const vision::CadModel& model, int face, double px_per_m) {
  const auto& loop = model.faces[static_cast<std::size_t>(face)].vertices;
  const Vector3d& v0 = model.vertices[static_cast<std::size_t>(loop[0])];
  const Vector3d& v2 = model.vertices[static_cast<std::size_t>(loop[2])];
  const Vector3d& v3 = model.vertices[static_cast<std::size_t>(loop[3])];
  return {static_cast<int>(std::lround((v2 - v3).norm() * px_per_m)), static_cast<int>(std::lround((v0 - v3).norm() * px_per_m))};
}

EnvironmentPlane wall(const Vector3d& centre_world, const Vector3d& facing_world, double width_m, double height_m,
                      int texture) {
  EnvironmentPlane p;
  const Vector3d z = facing_world.normalized();
  const Vector3d y = Vector3d::UnitZ();
  p.world_T_plane.linear().col(0) = y.cross(z);
  p.world_T_plane.linear().col(1) = y;
  p.world_T_plane.linear().col(2) = z;
  p.world_T_plane.translation() = centre_world;
  p.width_m = width_m;
  p.height_m = height_m;
  p.texture = texture;
  return p;
}

EnvironmentPlane floor_plane(double z_m, const Vector3d& centre, double width_m, double depth_m, int texture,
                             double px_per_m) {
  EnvironmentPlane p;
  p.world_T_plane.translation() = Vector3d(centre.x(), centre.y(), z_m);
  p.width_m = width_m;
  p.height_m = depth_m;
  p.texture = texture;
  p.tex_px_per_m = px_per_m;
  p.receives_shadow = true;
  return p;
}

// Four walls around (cx, cy) from z0 up to z0 + height, each textured, facing inwards.
void add_walls(Scene& s, double cx, double cy, double half_x, double half_y, double z0, double height,
               const std::array<int, 4>& textures) {
  const double zc = z0 + height / 2;
  s.background.planes.push_back(wall({cx, cy + half_y, zc}, -Vector3d::UnitY(), 2 * half_x, height, textures[0]));
  s.background.planes.push_back(wall({cx - half_x, cy, zc}, Vector3d::UnitX(), 2 * half_y, height, textures[1]));
  s.background.planes.push_back(wall({cx + half_x, cy, zc}, -Vector3d::UnitX(), 2 * half_y, height, textures[2]));
  s.background.planes.push_back(wall({cx, cy - half_y, zc}, Vector3d::UnitY(), 2 * half_x, height, textures[3]));
}

void set_view(Scene& s, const Vector3d& camera, const Vector3d& target, double min_m, double max_m) {
  s.view.camera_world = camera;
  s.view.target_world = target;
  s.view.distance_m = (camera - target).norm();
  s.view.min_distance_m = min_m;
  s.view.max_distance_m = max_m;
}

// ---- the scenes -----------------------------------------------------------------------------

std::expected<void, std::string> build_mockup_walk(Scene& s, std::uint64_t print_seed) {
  const int px_per_m = 500;  // 2 mm per texture pixel
  // Plates: one grey family; welds only in the texture.
  std::vector<int> face_material;
  for (std::size_t part = 0; part < std::size(kMockupParts); ++part) {
    const MockupPart& p = kMockupParts[part];
    const Vector3d size = p.hi - p.lo;
    std::vector<texture::Seam> seams;
    // Plate mapping: front view (u = +x, v = -z) for vertical parts, top view (u = +x, v = -y) for the deck.
    const bool horizontal = std::string_view(p.name) == "deck";
    const cv::Size tex(std::max(8, static_cast<int>(size.x() * px_per_m)),
                       std::max(8, static_cast<int>((horizontal ? size.y() : size.z()) * px_per_m)));
    auto tx = [&](double x) { return (x - p.lo.x()) * px_per_m; };
    auto tv = [&](double v) { return horizontal ? (p.hi.y() - v) * px_per_m : (p.hi.z() - v) * px_per_m; };
    if (std::string_view(p.name) == "bulkhead") {
      seams.push_back({{tx(-0.15), 0}, {tx(-0.15), static_cast<double>(tex.height)}});  // butt weld
      seams.push_back({{0, tv(0.42)}, {static_cast<double>(tex.width), tv(0.42)}});
      seams.push_back({{tx(0.188), tv(0.8)}, {tx(0.188), tv(0.02)}});  // fillet welds of the T web
      seams.push_back({{tx(0.212), tv(0.8)}, {tx(0.212), tv(0.02)}});
      seams.push_back({{0, tv(0.028)}, {static_cast<double>(tex.width), tv(0.028)}});  // to the deck
    } else if (horizontal) {
      seams.push_back({{tx(0.05), 0}, {tx(0.05), static_cast<double>(tex.height)}});
      seams.push_back({{0, tv(0.192)}, {static_cast<double>(tex.width), tv(0.192)}});
      for (double y : {-0.260, -0.230, -0.200}) seams.push_back({{tx(-0.45), tv(y - 0.004)}, {tx(0.45), tv(y - 0.004)}});
    }
    Material m = grey(p.reflectance);
    m.texture = add_texture(s, texture::steel_plate(tex, seams, print(100 + part, print_seed)));
    m.tex_origin_obj = horizontal ? Vector3d(p.lo.x(), p.hi.y(), p.hi.z()) : Vector3d(p.lo.x(), p.lo.y(), p.hi.z());
    m.tex_u_obj = Vector3d::UnitX();
    m.tex_v_obj = horizontal ? -Vector3d::UnitY() : -Vector3d::UnitZ();
    m.tex_px_per_m = px_per_m;
    const int mat = add_material(s, m);
    for (int f = 0; f < 6; ++f) face_material.push_back(mat);
  }
  s.object_mesh = mesh_from_model(s.model, face_material);

  // A workshop around it: cluttered walls 3 m away, a concrete floor.
  std::array<int, 4> walls{};
  for (int i = 0; i < 4; ++i) walls[static_cast<std::size_t>(i)] = add_texture(s, texture::clutter({1024, 512}, 200 + i));
  add_walls(s, 0, 0, 3.0, 3.0, 0.0, 3.0, walls);
  s.background.planes.push_back(floor_plane(0.0, Vector3d::Zero(), 6.0, 6.0, add_texture(s, texture::concrete({512, 512}, 7)), 256));
  s.background.plain_bgr = {0.45f, 0.45f, 0.42f};
  s.light.direction_world = Vector3d(-0.4, -0.6, 1.0).normalized();
  s.light.ambient = 0.45;
  s.light.diffuse = 0.55;
  s.shadows.enabled = true;
  s.shadows.ground_z_m = 0.0;
  s.shadows.softness_px = 2.5;
  set_view(s, {0.35, -1.45, 0.8}, {0.05, 0.0, 0.3}, 1.0, 1.8);
  s.variety_limits = {.object_yaw_deg = 10, .object_offset_m = 0.05, .orbit_deg = 12, .start_shift_m = 0.15,
                      .heading_deg = 4, .passing_pole = true};
  return {};
}

std::expected<void, std::string> build_lampshade(Scene& s, std::uint64_t print_seed) {
  constexpr double table_z = -0.25;
  // The shade: a smooth cone (the model's 36 facets would show as a polygon), open at both ends.
  Material shade = plain(0.62f, 0.76f, 0.86f);
  shade.texture = add_texture(s, texture::fabric({256, 256}, print(11, print_seed)));
  shade.tex_u_obj = Vector3d::UnitX();
  shade.tex_v_obj = -Vector3d::UnitZ();
  shade.tex_px_per_m = 1600;
  shade.gradient_per_m_obj = Vector3d(1.6, 0.9, 0.0);  // reflectance changes around the rim ...
  shade.gradient_swing = 0.8;                           // ... and that change drifts over time
  shade.change_amplitude = 0.12;
  shade.change_period_s = 7.0;
  const int shade_mat = add_material(s, shade);
  s.object_mesh.closed = false;
  add_frustum(s.object_mesh, Eigen::Isometry3d::Identity(), kShadeBottomRadius, kShadeTopRadius, kShadeHeight, 256,
              Caps::None, shade_mat);

  // The lamp under it: a base on the table and a stem up into the shade (scenery, untracked).
  const int metal = add_material(s, plain(0.18f, 0.2f, 0.22f));
  Mesh lamp;
  add_frustum(lamp, Eigen::Isometry3d(Eigen::Translation3d(0, 0, table_z)), 0.085, 0.075, 0.025, 96, Caps::Both, metal);
  add_frustum(lamp, Eigen::Isometry3d(Eigen::Translation3d(0, 0, table_z + 0.025)), 0.009, 0.009, 0.36 - 0.025, 48,
              Caps::Both, metal);
  s.scenery.push_back(std::move(lamp));

  // A thin arm (sleeve and hand) that sweeps in front of the shade.
  const int sleeve = add_material(s, plain(0.35f, 0.22f, 0.15f));
  Mesh arm;
  add_frustum(arm, Eigen::Isometry3d::Identity(), 0.022, 0.03, 0.6, 48, Caps::Both, sleeve);
  s.occluders.push_back(std::move(arm));
  OccluderPath path;
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.linear() = Eigen::AngleAxisd(0.35, Vector3d::UnitY()).toRotationMatrix();  // leaning arm, hand low
  start.translation() = Vector3d(-0.45, -0.22, 0.02);
  Eigen::Isometry3d end = start;
  end.translation() = Vector3d(0.40, -0.22, 0.06);
  path.world_T_start = start;
  path.world_T_end = end;
  path.start_s = 1.0;
  path.period_s = 6.0;
  s.occluder_paths.push_back(path);

  auto street = scene_photo("building.jpg");
  if (!street) return std::unexpected(street.error());
  auto board = scene_photo("board.jpg");
  if (!board) return std::unexpected(board.error());
  const int t_street = add_texture(s, *street), t_board = add_texture(s, *board);
  const int t_clutter = add_texture(s, texture::clutter({1024, 600}, 31));
  add_walls(s, 0, 0, 1.2, 1.0, table_z, 1.6, {t_street, t_clutter, t_board, t_clutter});
  s.background.planes.push_back(floor_plane(table_z, Vector3d::Zero(), 2.4, 2.0, add_texture(s, texture::wood({512, 512}, 12)), 700));
  s.background.plain_bgr = {0.8f, 0.75f, 0.7f};
  s.light.direction_world = Vector3d(0.5, -0.4, 1.0).normalized();
  s.shadows.enabled = true;
  s.shadows.ground_z_m = table_z;
  set_view(s, {0.05, -0.62, 0.22}, {0.0, 0.0, 0.07}, 0.45, 1.0);
  // The shade stays on its lamp (no offset); turning it only turns its reflectance gradient.
  s.variety_limits = {.object_yaw_deg = 180, .object_offset_m = 0, .orbit_deg = 25, .start_shift_m = 0.03,
                      .heading_deg = 5, .passing_pole = false};
  return {};
}

std::expected<void, std::string> build_box_clutter(Scene& s, std::uint64_t print_seed) {
  std::vector<int> face_material;
  constexpr double px_per_m = 3000;  // 0.33 mm per texture pixel: sharp from 0.35 m
  for (int f = 0; f < 6; ++f) {
    Material m = plain(1.f, 1.f, 1.f);
    map_texture_on_face(m, s.model, f, px_per_m);
    const cv::Size tex = face_texture_size(s.model, f, px_per_m);
    m.texture = add_texture(s, texture::package_face(tex, f, print(40 + static_cast<std::uint64_t>(f), print_seed)));
    face_material.push_back(add_material(s, m));
  }
  s.object_mesh = mesh_from_model(s.model, face_material);

  auto board = scene_photo("board.jpg");
  if (!board) return std::unexpected(board.error());
  auto street = scene_photo("building.jpg");
  if (!street) return std::unexpected(street.error());
  auto desk = scene_photo("stuff.jpg");
  if (!desk) return std::unexpected(desk.error());
  const int t_board = add_texture(s, *board), t_street = add_texture(s, *street), t_desk = add_texture(s, *desk);
  const int t_clutter = add_texture(s, texture::clutter({1024, 640}, 41));
  add_walls(s, 0, 0, 1.0, 1.0, 0.0, 1.2, {t_board, t_clutter, t_street, t_desk});
  s.background.planes.push_back(floor_plane(0.0, Vector3d::Zero(), 2.0, 2.0, add_texture(s, texture::wood({512, 512}, 42)), 800));
  s.background.plain_bgr = {0.85f, 0.85f, 0.85f};
  s.light.direction_world = Vector3d(-0.3, -0.5, 1.0).normalized();
  s.shadows.enabled = true;
  s.shadows.ground_z_m = 0.0;
  set_view(s, {0.12, -0.5, 0.32}, {0.0, 0.0, 0.05}, 0.35, 0.9);
  // Turned by up to 35 deg and seen from up to 25 deg around: still two sides and the top.
  s.variety_limits = {.object_yaw_deg = 35, .object_offset_m = 0.04, .orbit_deg = 25, .start_shift_m = 0.03,
                      .heading_deg = 5, .passing_pole = true};
  return {};
}

std::expected<void, std::string> build_office_pan(Scene& s, std::uint64_t print_seed) {
  // Materials 0..5 as the model's faces use them: floor, back wall, left wall, frame, desk top, legs.
  Material floor = plain(1.f, 1.f, 1.f);
  floor.texture = add_texture(s, texture::parquet({1024, 1024}, print(51, print_seed)));
  floor.tex_u_obj = Vector3d::UnitX();
  floor.tex_v_obj = -Vector3d::UnitY();
  floor.tex_px_per_m = 400;
  add_material(s, floor);
  Material back = plain(0.72f, 0.78f, 0.80f);
  back.texture = add_texture(s, texture::plaster({512, 512}, cv::Scalar(245, 245, 245), print(52, print_seed)));
  back.tex_u_obj = Vector3d::UnitX();
  back.tex_v_obj = -Vector3d::UnitZ();
  back.tex_px_per_m = 200;
  back.gradient_per_m_obj = Vector3d(-0.06, 0, 0);  // light falls off away from the window side
  add_material(s, back);
  Material left = back;
  left.albedo_bgr = {0.66f, 0.74f, 0.78f};
  left.tex_u_obj = -Vector3d::UnitY();
  add_material(s, left);
  add_material(s, plain(0.86f, 0.88f, 0.88f));  // door frame: white paint
  Material top = plain(1.f, 1.f, 1.f);
  top.texture = add_texture(s, texture::wood({512, 512}, print(53, print_seed)));
  top.tex_u_obj = Vector3d::UnitX();
  top.tex_v_obj = -Vector3d::UnitY();
  top.tex_px_per_m = 500;
  add_material(s, top);
  add_material(s, plain(0.12f, 0.12f, 0.13f));  // legs: black steel
  std::vector<int> face_material = {0, 1, 2};
  for (const auto& b : kOfficeBoxes)
    for (int f = 0; f < 6; ++f) face_material.push_back(b.material);
  s.object_mesh = mesh_from_model(s.model, face_material);

  // Untracked things on the walls: the door leaf and its handle, a poster, a skirting shadow line.
  Mesh scenery;
  scenery.closed = false;
  const int door = add_material(s, plain(0.35f, 0.5f, 0.62f));
  add_quad(scenery, {2.20, -0.004, 0.0}, {3.10, -0.004, 0.0}, {3.10, -0.004, 2.05}, {2.20, -0.004, 2.05}, door);
  const int brass = add_material(s, plain(0.2f, 0.55f, 0.7f));
  add_box(scenery, Eigen::Isometry3d(Eigen::Translation3d(2.98, -0.03, 1.0)), {0.12, 0.02, 0.025}, brass);
  auto graffiti = scene_photo("graf1.jpg");
  if (!graffiti) return std::unexpected(graffiti.error());
  Material poster = plain(1.f, 1.f, 1.f);
  poster.texture = add_texture(s, *graffiti);
  poster.tex_origin_obj = Vector3d(0.005, -2.3, 1.85);
  poster.tex_u_obj = Vector3d::UnitY();
  poster.tex_v_obj = -Vector3d::UnitZ();
  poster.tex_px_per_m = graffiti->cols / 0.9;
  const int poster_mat = add_material(s, poster);
  add_quad(scenery, {0.005, -2.3, 1.85 - 0.72}, {0.005, -1.4, 1.85 - 0.72}, {0.005, -1.4, 1.85}, {0.005, -2.3, 1.85},
           poster_mat);
  s.scenery.push_back(std::move(scenery));

  // The rest of the room is environment: right wall, front wall, ceiling.
  const int t_wall = add_texture(s, texture::plaster({512, 512}, cv::Scalar(200, 212, 218), 54));
  EnvironmentPlane right = wall({kRoomX, -kRoomY / 2, kRoomH / 2}, -Vector3d::UnitX(), kRoomY, kRoomH, t_wall);
  EnvironmentPlane front = wall({kRoomX / 2, -kRoomY, kRoomH / 2}, Vector3d::UnitY(), kRoomX, kRoomH, t_wall);
  right.tex_px_per_m = front.tex_px_per_m = 200;
  s.background.planes.push_back(right);
  s.background.planes.push_back(front);
  EnvironmentPlane ceiling;
  ceiling.world_T_plane.linear() = Eigen::AngleAxisd(std::numbers::pi, Vector3d::UnitX()).toRotationMatrix();
  ceiling.world_T_plane.translation() = Vector3d(kRoomX / 2, -kRoomY / 2, kRoomH);
  ceiling.width_m = kRoomX;
  ceiling.height_m = kRoomY;
  ceiling.tint_bgr = {0.85f, 0.87f, 0.88f};
  s.background.planes.push_back(ceiling);
  s.background.plain_bgr = {0.8f, 0.8f, 0.8f};
  s.light.direction_world = Vector3d(0.3, -0.5, 1.0).normalized();
  s.light.ambient = 0.55;
  s.light.diffuse = 0.45;
  s.shadows.enabled = false;
  set_view(s, {3.5, -4.7, 0.9}, {1.7, 0.0, 0.9}, 2.0, 6.0);
  // The object is the room: it does not move, and the drive stays inside it.
  s.variety_limits = {.object_yaw_deg = 0, .object_offset_m = 0, .orbit_deg = 0, .start_shift_m = 0.25,
                      .heading_deg = 3, .passing_pole = false};
  return {};
}

// A table top with clutter around it: a wooden floor plane at z = 0 and four walls of photos
// and clutter (can, bowl).
std::expected<void, std::string> add_table_surroundings(Scene& s, std::uint64_t clutter_seed, std::uint64_t wood_seed) {
  auto desk = scene_photo("stuff.jpg");
  if (!desk) return std::unexpected(desk.error());
  auto street = scene_photo("building.jpg");
  if (!street) return std::unexpected(street.error());
  auto graffiti = scene_photo("graf1.jpg");
  if (!graffiti) return std::unexpected(graffiti.error());
  const int t_desk = add_texture(s, *desk), t_street = add_texture(s, *street), t_graf = add_texture(s, *graffiti);
  const int t_clutter = add_texture(s, texture::clutter({1024, 640}, clutter_seed));
  add_walls(s, 0, 0, 1.0, 1.0, 0.0, 1.2, {t_desk, t_clutter, t_graf, t_street});
  s.background.planes.push_back(floor_plane(0.0, Vector3d::Zero(), 2.0, 2.0, add_texture(s, texture::wood({512, 512}, wood_seed)), 800));
  s.background.plain_bgr = {0.8f, 0.8f, 0.8f};
  s.shadows.enabled = true;
  s.shadows.ground_z_m = 0.0;
  return {};
}

std::expected<void, std::string> build_can(Scene& s, std::uint64_t print_seed) {
  // Smooth side (256 segments; the model's 32 facets would show as a polygon) in three bands:
  // a metal foot, the printed label, a metal shoulder; a lid and a bottom.
  constexpr double foot = 0.012, shoulder = 0.108, px_per_m = 3000;
  const int metal = add_material(s, plain(0.52f, 0.54f, 0.56f));
  const int lid = add_material(s, plain(0.42f, 0.44f, 0.46f));
  Material label = plain(1.f, 1.f, 1.f);
  // Planar mapping seen from -y: the print spans the can's width; toward the silhouette it is
  // foreshortened as a real label is.
  label.tex_origin_obj = Vector3d(-kCanRadius, 0, shoulder);
  label.tex_u_obj = Vector3d::UnitX();
  label.tex_v_obj = -Vector3d::UnitZ();
  label.tex_px_per_m = px_per_m;
  label.texture = add_texture(s, texture::package_face({static_cast<int>(std::lround(2 * kCanRadius * px_per_m)),
                                                         static_cast<int>(std::lround((shoulder - foot) * px_per_m))},
                                                        1, print(61, print_seed)));
  const int label_mat = add_material(s, label);
  auto at_z = [](double z) { return Eigen::Isometry3d(Eigen::Translation3d(0, 0, z)); };
  add_frustum(s.object_mesh, at_z(0), kCanRadius, kCanRadius, foot, 256, Caps::None, metal);
  add_frustum(s.object_mesh, at_z(foot), kCanRadius, kCanRadius, shoulder - foot, 256, Caps::None, label_mat);
  add_frustum(s.object_mesh, at_z(shoulder), kCanRadius, kCanRadius, kCanHeight - shoulder, 256, Caps::None, metal);
  add_disc(s.object_mesh, at_z(kCanHeight), kCanRadius, 0, 256, lid);
  Eigen::Isometry3d bottom = at_z(0);
  bottom.linear() = Eigen::AngleAxisd(std::numbers::pi, Vector3d::UnitX()).toRotationMatrix();
  add_disc(s.object_mesh, bottom, kCanRadius, 0, 256, lid);

  if (auto ok = add_table_surroundings(s, 71, 72); !ok) return ok;
  s.light.direction_world = Vector3d(0.4, -0.5, 1.0).normalized();
  set_view(s, {0.05, -0.42, 0.2}, {0.0, 0.0, 0.06}, 0.3, 0.8);
  s.variety_limits = {.object_yaw_deg = 30, .object_offset_m = 0.04, .orbit_deg = 30, .start_shift_m = 0.03,
                      .heading_deg = 5, .passing_pole = true};
  return {};
}

std::expected<void, std::string> build_bowl(Scene& s, std::uint64_t print_seed) {
  (void)print_seed;  // a plain glaze: nothing printed
  // Smooth: 48 profile rings of 256 segments (normals of neighbouring rings differ by 1 deg), one
  // open surface whose back is the inside seen through the opening, and a flat inner bottom.
  Material glaze = plain(0.72f, 0.50f, 0.30f);
  glaze.gradient_per_m_obj = Vector3d(0, 0, 1.5);  // a little lighter toward the rim, as glazes run
  const int glaze_mat = add_material(s, glaze);
  constexpr int render_rings = 48;
  s.object_mesh.closed = false;
  for (int i = 0; i < render_rings; ++i) {
    const Eigen::Vector2d a = bowl_profile(static_cast<double>(i) / render_rings);
    const Eigen::Vector2d b = bowl_profile(static_cast<double>(i + 1) / render_rings);
    add_frustum(s.object_mesh, Eigen::Isometry3d(Eigen::Translation3d(0, 0, a.y())), a.x(), b.x(), b.y() - a.y(), 256,
                Caps::None, glaze_mat);
  }
  add_disc(s.object_mesh, Eigen::Isometry3d::Identity(), kBowlFootRadius, 0, 256, glaze_mat);

  if (auto ok = add_table_surroundings(s, 81, 82); !ok) return ok;
  s.light.direction_world = Vector3d(-0.3, -0.5, 1.0).normalized();
  set_view(s, {0.05, -0.45, 0.3}, {0.0, 0.0, 0.04}, 0.3, 0.8);
  s.variety_limits = {.object_yaw_deg = 180, .object_offset_m = 0.04, .orbit_deg = 30, .start_shift_m = 0.03,
                      .heading_deg = 5, .passing_pole = true};
  return {};
}

}  // namespace

const std::vector<std::string>& scene_names() {
  static const std::vector<std::string> names = {"mockup_walk", "lampshade", "box_clutter", "office_pan", "can", "bowl"};
  return names;
}

std::optional<std::string_view> scene_model_cao(std::string_view name) {
  return builtin_asset_text("scenes/" + std::string(name) + ".cao");
}

std::expected<vision::CadModel, std::string> make_scene_model(std::string_view name) { return model_of(name); }

std::expected<Scene, std::string> make_scene(std::string_view name, std::uint64_t print_seed) {
  auto model = model_of(name);
  if (!model) return std::unexpected(model.error());
  Scene s;
  s.name = std::string(name);
  s.model = std::move(*model);
  std::expected<void, std::string> ok;
  if (name == "mockup_walk") ok = build_mockup_walk(s, print_seed);
  else if (name == "lampshade") ok = build_lampshade(s, print_seed);
  else if (name == "box_clutter") ok = build_box_clutter(s, print_seed);
  else if (name == "office_pan") ok = build_office_pan(s, print_seed);
  else if (name == "can") ok = build_can(s, print_seed);
  else ok = build_bowl(s, print_seed);
  if (!ok) return std::unexpected(ok.error());
  return s;
}

}  // namespace epichead::sim
