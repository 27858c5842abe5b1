// The built-in scenes: render meshes, appearance, environment, light (their tracked objects'
// models: scene_models.cpp).
#include "epichead/sim/scene_library.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "epichead/sim/builtin_asset.h"
#include "scene_dressing.h"
#include "scene_photo.h"
#include "scene_shapes.h"
#include "texture.h"

namespace epichead::sim {
namespace {

using Eigen::Vector3d;
using namespace scenes;

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

std::expected<Scene, std::string> make_scene(std::string_view name, std::uint64_t print_seed) {
  auto model = make_scene_model(name);
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
