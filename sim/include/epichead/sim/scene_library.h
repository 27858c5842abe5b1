#pragma once
// The built-in scenes. Each puts its tracked object at the world origin (world z up) and
// says in Scene::view where a camera should look from.
//
//   mockup_walk  a ship-section mockup, 1.0 m wide x 0.5 m deep x 0.8 m high (origin: floor under
//                its centre), seen from 1-1.5 m by a walking robot: grey plates of nearly equal
//                reflectance (0.55-0.62) with faint weld seams (texture, not in the model), a T-truss
//                (flange and web plates), three flat-bar stiffeners 3 cm apart along the bottom
//                front; shadows on a concrete floor; lighting drift via FrameInput::illumination_gain.
//   lampshade    a truncated cone (bottom radius 0.12 m, top 0.07 m, height 0.16 m; origin: bottom
//                rim centre, axis +z) on a lamp over a table (z = -0.25 m) in front of photos; its
//                model has the two rim circles and 36 facets (below the crease angle); reflectance
//                varies along the rim and over time; a thin arm (occluder 0) sweeps past.
//   box_clutter  a printed package of 0.20 x 0.15 x 0.10 m (origin: bottom centre) on a wooden
//                table, photos all around.
//   office_pan   a room corner seen from a wheeled robot: two walls and the floor, a door frame,
//                a desk with legs; 4 m x 5 m x 2.5 m; corner at the origin, back wall y = 0, left
//                wall x = 0, the room toward +x, -y.
//   can          a printed can (cylinder, radius 0.04 m, height 0.12 m; origin: bottom centre, axis
//                +z) on a wooden table with photos and clutter around; rendered smooth, modelled by
//                32 facets (below the crease angle) and the two rim circles.
//   bowl         a glazed bowl (body of revolution with a curved profile: foot radius 0.05 m, rim
//                radius 0.094 m at 0.087 m; origin: bottom centre, axis +z) on the same kind of
//                table; rendered smooth (48 x 256 facets), modelled by 4 rings of 32 facets (12 deg
//                apart, below the crease angle) and the open top's rim circle.
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "epichead/sim/scene.h"

namespace epichead::sim {

// The names make_scene accepts, in the order above.
const std::vector<std::string>& scene_names();

// Builds a built-in scene (model, meshes, procedural textures; photos built into the program).
// `print_seed` 0 gives the object's built-in procedural prints (package faces, label, plates),
// any other value a different set (scene variety). Errors name the unknown scene (with the
// known ones) or the photo that could not be read.
std::expected<Scene, std::string> make_scene(std::string_view name, std::uint64_t print_seed = 0);

// The tracked object's wire-frame of a built-in scene, as written to sim/scenes/<name>.cao
// (a sequence's model.cao is a copy of that file).
std::expected<vision::CadModel, std::string> make_scene_model(std::string_view name);

// The text of a built-in scene's CAO file (sim/scenes/<name>.cao, built into the program); a
// tool that needs the model as a file writes this text. nullopt for an unknown scene.
std::optional<std::string_view> scene_model_cao(std::string_view name);

}  // namespace epichead::sim
