#pragma once
// Private to the built-in scenes: what scene_library.cpp dresses its scenes with (materials,
// texture mappings, environment walls and floors, the camera's view, a table's surroundings).
#include <array>
#include <cstdint>
#include <expected>
#include <string>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "epichead/sim/scene.h"
#include "epichead/vision/cao_model.h"

namespace epichead::sim::scenes {

// The seed of one of the object's procedural prints: the built-in one for print_seed 0, else a
// different print for each print_seed (scene variety draws new package prints, labels, plates).
std::uint64_t print(std::uint64_t builtin_seed, std::uint64_t print_seed);

// Append to the scene; return the new index.
int add_texture(Scene& s, cv::Mat t);
int add_material(Scene& s, const Material& m);
// Untextured materials: a grey reflectance, a BGR albedo.
Material grey(double reflectance);
Material plain(float b, float g, float r);

// Texture mapping that shows the texture upright on a face seen from outside: origin at the
// face's top-left corner (the loop's last vertex of a quad), u along the top edge, v down the left edge.
void map_texture_on_face(Material& m, const vision::CadModel& model, int face, double px_per_m);
// The texture size that covers a quad face exactly at px_per_m.
cv::Size face_texture_size(const vision::CadModel& model, int face, double px_per_m);

// An upright environment wall centred at `centre_world`, seen from the side `facing_world` points to.
EnvironmentPlane wall(const Eigen::Vector3d& centre_world, const Eigen::Vector3d& facing_world, double width_m,
                      double height_m, int texture);
// A horizontal floor at height z_m around `centre` that receives shadows.
EnvironmentPlane floor_plane(double z_m, const Eigen::Vector3d& centre, double width_m, double depth_m, int texture,
                             double px_per_m);
// Four walls around (cx, cy) from z0 up to z0 + height, each textured, facing inwards.
void add_walls(Scene& s, double cx, double cy, double half_x, double half_y, double z0, double height,
               const std::array<int, 4>& textures);
// Where a camera should look from and at, and the distances a drawn camera path may take.
void set_view(Scene& s, const Eigen::Vector3d& camera, const Eigen::Vector3d& target, double min_m, double max_m);

// A table top with clutter around it: a wooden floor plane at z = 0 and four walls of photos
// and clutter (can, bowl).
std::expected<void, std::string> add_table_surroundings(Scene& s, std::uint64_t clutter_seed, std::uint64_t wood_seed);

}  // namespace epichead::sim::scenes
