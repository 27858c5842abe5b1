#pragma once
// Private to the built-in scenes: the tracked objects' dimensions, which their models
// (scene_models.cpp) and their rendered meshes (scene_library.cpp) share, so both show one shape.
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace epichead::sim::scenes {

// Lamp shade geometry (object frame: bottom rim centre at the origin, axis +z).
inline constexpr double kShadeBottomRadius = 0.12, kShadeTopRadius = 0.07, kShadeHeight = 0.16;
inline constexpr int kShadeFacets = 36;

// Can (object frame: bottom centre at the origin, axis +z): a cylinder modelled, as ViSP users do,
// by its facets and its two rim circles; rendered smooth.
inline constexpr double kCanRadius = 0.04, kCanHeight = 0.12;
inline constexpr int kCanFacets = 32;

// Bowl (object frame: bottom centre at the origin, axis +z): the profile's slope angle grows
// linearly along its arc length s, so r(s) and z(s) are closed-form and the render can sample the
// same curve finely. The model's rings are points of that curve; facets of neighbouring rings
// differ by (end - start) / rings = 12 deg, below the 20 deg crease angle, so ring edges are not
// tracked (no image edge there), only the rim circle and the silhouette.
inline constexpr double kBowlFootRadius = 0.05, kBowlProfileLength = 0.10;
inline constexpr double kBowlStartSlopeRad = 40.0 * std::numbers::pi / 180, kBowlEndSlopeRad = 88.0 * std::numbers::pi / 180;
inline constexpr int kBowlRings = 4, kBowlFacets = 32;
// (radius, height) of the bowl profile at fraction u (0 = foot, 1 = rim) of its arc length.
inline Eigen::Vector2d bowl_profile(double u) {
  const double k = (kBowlEndSlopeRad - kBowlStartSlopeRad) / kBowlProfileLength;
  const double theta = kBowlStartSlopeRad + u * (kBowlEndSlopeRad - kBowlStartSlopeRad);
  return {kBowlFootRadius + (std::sin(theta) - std::sin(kBowlStartSlopeRad)) / k,
          (std::cos(kBowlStartSlopeRad) - std::cos(theta)) / k};
}

// Box of box_clutter: 0.20 x 0.15 x 0.10 m standing on the table, bottom centre at the origin.
inline const Eigen::Vector3d kPackageLo(-0.10, -0.075, 0.0), kPackageHi(0.10, 0.075, 0.10);

// mockup_walk parts (object frame: floor at z = 0, viewer on the -y side).
struct MockupPart { const char* name; Eigen::Vector3d lo, hi; double reflectance; };
inline const MockupPart kMockupParts[] = {
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
inline constexpr double kRoomX = 4.0, kRoomY = 5.0, kRoomH = 2.5;
struct OfficeBox { Eigen::Vector3d lo, hi; int material; };  // materials: 3 frame, 4 desk top, 5 desk legs
inline const OfficeBox kOfficeBoxes[] = {
    {{2.13, -0.02, 0.0}, {2.20, 0.0, 2.12}, 3},   // door frame: left jamb
    {{3.10, -0.02, 0.0}, {3.17, 0.0, 2.12}, 3},   // right jamb
    {{2.20, -0.02, 2.05}, {3.10, 0.0, 2.12}, 3},  // head
    {{0.30, -0.75, 0.72}, {1.50, -0.05, 0.75}, 4},  // desk top
    {{0.33, -0.72, 0.0}, {0.37, -0.68, 0.72}, 5},  // legs
    {{1.43, -0.72, 0.0}, {1.47, -0.68, 0.72}, 5},
    {{0.33, -0.12, 0.0}, {0.37, -0.08, 0.72}, 5},
    {{1.43, -0.12, 0.0}, {1.47, -0.08, 0.72}, 5},
};

}  // namespace epichead::sim::scenes
