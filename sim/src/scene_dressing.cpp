// What the built-in scenes are dressed with; see scene_dressing.h.
#include "scene_dressing.h"

#include <cmath>

#include "scene_photo.h"
#include "texture.h"

namespace epichead::sim::scenes {

using Eigen::Vector3d;

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

}  // namespace epichead::sim::scenes
