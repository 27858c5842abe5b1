#pragma once
// What the simulator draws: the tracked object (its wire-frame model and how it looks), static
// scenery, moving occluders, the environment behind them (photos on far walls, a floor), the
// light and cast shadows. World frame: z up, metres; the tracked object sits at the origin.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/vision/cao_model.h"
#include "epichead/vision/look_at.h"

namespace epichead::sim {

// Linear diffuse reflectance (albedo) or radiance, blue-green-red like OpenCV images, 0..1.
using ColorBgr = Eigen::Vector3f;

// How a surface looks. Its reflectance at object point X and time t is
//   albedo_bgr * texture(X) * (1 + g(t) . (X - gradient_origin_obj)) * (1 + change_amplitude * s(t))
// with s(t) = sin(2 pi t / change_period_s + change_phase_rad) and
// g(t) = gradient_per_m_obj * (1 + gradient_swing * s(t)): a gradient along the face that itself
// drifts over time (a trackers' cue model must follow it). The result is clamped to 0..1.
struct Material {
  ColorBgr albedo_bgr{0.6f, 0.6f, 0.6f};
  // Index into Scene::textures, or -1. The texture multiplies the albedo; it repeats. Texture
  // pixel (u, v) = ((X - tex_origin_obj) . tex_u_obj, (X - tex_origin_obj) . tex_v_obj) * tex_px_per_m.
  int texture = -1;
  Eigen::Vector3d tex_origin_obj = Eigen::Vector3d::Zero();
  Eigen::Vector3d tex_u_obj = Eigen::Vector3d::UnitX();  // unit: direction of texture columns
  Eigen::Vector3d tex_v_obj = Eigen::Vector3d::UnitY();  // unit: direction of texture rows
  double tex_px_per_m = 1000;
  Eigen::Vector3d gradient_per_m_obj = Eigen::Vector3d::Zero();  // relative albedo change per metre
  Eigen::Vector3d gradient_origin_obj = Eigen::Vector3d::Zero();
  double gradient_swing = 0;    // relative change of the gradient over time
  double change_amplitude = 0;  // relative change of the whole albedo over time
  double change_period_s = 10;
  double change_phase_rad = 0;
};

// A triangle mesh in its own frame. Flat faces repeat their corner vertices with the face normal;
// curved surfaces (cone, cylinder) share vertices with smooth normals so facets do not show.
struct Mesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3f> normals;             // unit, per vertex, pointing out of the surface
  std::vector<std::array<int, 3>> triangles;        // CCW seen from the side the normals point to
  std::vector<int> triangle_material;               // index into Scene::materials, per triangle
  // Every surface bounds a solid seen only from outside: triangles facing away may be culled.
  // False for open surfaces (a single plate, room walls seen from inside): both sides are drawn.
  bool closed = true;
};

// Mesh builders. `frame_T_part` places the part inside the mesh's frame.
// A box of the given edge lengths centred on the part origin, axes along the part axes.
void add_box(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, const Eigen::Vector3d& size_m, int material);
// A truncated cone (cylinder when the radii are equal) along the part z axis from z = 0 (radius_a_m)
// to z = height_m (radius_b_m), with `segments` facets and smooth normals; caps optional.
enum class Caps { None, Both };
void add_frustum(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, double radius_a_m, double radius_b_m,
                 double height_m, int segments, Caps caps, int material);
// A flat disc in the part xy plane facing +z (or a ring when inner_radius_m > 0).
void add_disc(Mesh& mesh, const Eigen::Isometry3d& frame_T_part, double radius_m, double inner_radius_m,
              int segments, int material);
// A planar quad with corners a, b, c, d (CCW seen from the side its normal points to).
void add_quad(Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
              const Eigen::Vector3d& d, int material);
// The faces of a CAO model as flat polygons (its triangulation); face i gets face_material[i],
// cylinder j face_material[faces + j] (face_material[0] where the list is short). Cylinders are
// tessellated with `cylinder_segments` facets and capped; circles are not drawn (draw a disc or
// a ring with add_disc where one should show).
Mesh mesh_from_model(const vision::CadModel& model, const std::vector<int>& face_material,
                     int cylinder_segments = 96);

// A textured rectangle of the environment (a photo on a far wall, the floor). It spans
// [-width_m/2, width_m/2] x [-height_m/2, height_m/2] in the xy plane of `world_T_plane` and is
// seen from its +z side; texture row 0 is at +y (the top of a wall whose y axis points up).
struct EnvironmentPlane {
  Eigen::Isometry3d world_T_plane = Eigen::Isometry3d::Identity();
  double width_m = 1, height_m = 1;
  int texture = -1;                    // index into Scene::textures; -1 = plain tint
  ColorBgr tint_bgr{1.f, 1.f, 1.f};    // multiplies the texture (or is the colour when plain)
  double tex_px_per_m = 0;             // 0: the texture is stretched over the whole rectangle
  bool receives_shadow = false;        // cast shadows of objects darken it (the floor)
};

// Everything behind the objects. The renderer assumes it is behind every object and occluder.
struct Background {
  ColorBgr plain_bgr{0.5f, 0.5f, 0.5f};   // seen where no plane is
  std::vector<EnvironmentPlane> planes;   // drawn in order: far walls first, floor last
};

// A distant light plus ambient light: radiance = reflectance * gain * (ambient + diffuse * max(0, n . l)).
struct Light {
  Eigen::Vector3d direction_world = Eigen::Vector3d(0.3, -0.5, 1.0).normalized();  // unit, toward the light
  double ambient = 0.4;
  double diffuse = 0.6;
};

// Shadows cast by objects (not occluders) onto environment planes marked receives_shadow: the
// object is projected along the light onto the plane z = ground_z_m (world), and the shadowed
// part of the plane keeps only `ambient` light (darkening = diffuse share removed).
struct Shadows {
  bool enabled = false;
  double ground_z_m = 0;
  double softness_px = 1.5;  // blur of the shadow border (penumbra)
};

// Where a camera should look from: the motion code places the robot or hand so that the object
// is in view from about `distance_m`.
struct ViewHint {
  Eigen::Vector3d target_world = Eigen::Vector3d::Zero();  // look at this point (object centre)
  Eigen::Vector3d camera_world{1, 0, 0};                   // a good camera position
  double distance_m = 1;                                   // |camera_world - target_world|
  double min_distance_m = 0.5, max_distance_m = 2;         // the object stays well framed in this range
};

// How far a seed's scene variety (scene_variety.h) may move things in this scene at variety 1:
// what keeps the scene plausible (a room does not turn, a lamp shade stays on its lamp) and the
// object in a useful, non-degenerate view.
struct VarietyLimits {
  double object_yaw_deg = 0;   // turn of the object on its support about world z
  double object_offset_m = 0;  // shift of the object on its support along world x and y
  double orbit_deg = 0;        // the camera's start turned about the object (world z)
  double start_shift_m = 0;    // and shifted along world x and y
  double heading_deg = 4;      // the body's heading turned
  bool passing_pole = false;   // a pole may pass in front of the object (scenes without occluders)
};

// A default path for an occluder: its pose moves linearly from world_T_start to world_T_end
// and back (a triangle wave of period_s), starting at start_s; before start_s it stays at start.
struct OccluderPath {
  Eigen::Isometry3d world_T_start = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d world_T_end = Eigen::Isometry3d::Identity();
  double start_s = 0;
  double period_s = 4;
};
// The pose of an occluder on its default path at time t_s (translation linear, rotation slerp).
Eigen::Isometry3d occluder_pose(const OccluderPath& path, double t_s);

// Camera placement is vision's (sim code and its users call it as sim::look_at too).
using vision::look_at;

struct Scene {
  std::string name;
  vision::CadModel model;        // the tracked object's wire-frame: what the tracker is given
  Mesh object_mesh;              // how the tracked object looks (finer than the model where curved)
  Eigen::Isometry3d world_T_obj = Eigen::Isometry3d::Identity();  // built-in scenes: identity
  std::vector<Mesh> scenery;     // fixed untracked objects, world frame (they cast shadows too)
  std::vector<Mesh> occluders;   // moving untracked objects, posed per sub-frame by the caller
  std::vector<OccluderPath> occluder_paths;  // a default path per occluder (may be ignored)
  std::vector<Material> materials;
  std::vector<cv::Mat> textures;  // 8-bit BGR, gamma-encoded like photos (decoded with the render gamma)
  Background background;
  Light light;
  Shadows shadows;
  ViewHint view;
  VarietyLimits variety_limits;
  int blur_subframes = 4;         // sub-frames per frame the scene is meant to be rendered with
  double exposure_s = 0.008;      // exposure time those sub-frames should span
};

}  // namespace epichead::sim
