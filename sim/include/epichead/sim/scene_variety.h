#pragma once
// Scene variety: a seed draws a scene that differs from the one the tracker was tuned on, so
// held-out seeds test robustness. Scaled by Scenario::variety (0 = the built-in scene exactly),
// the seed changes the background (photos and procedural textures on walls and floor, the plain
// colour), the light (direction, ambient/diffuse split, gain, a slow drift), the object's look
// (albedo scale and tint, procedural prints) and placement (yaw and offset on its support), the
// camera path (start, heading, aim, speed, sway and shake amplitude, step timing) and the
// occluders (timing and path of the scene's own, or a pole passing in front). Scenario::covers
// add a board that hides the object completely. Every draw keeps the object in view in every
// frame and visible against its background; the draws are recorded in sim_truth.json.
#include <cstdint>
#include <expected>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "epichead/sim/scenario.h"
#include "epichead/sim/scene.h"
#include "epichead/vision/camera.h"

namespace epichead::sim {

// What a seed drew. Values are the ones applied (after scaling by the variety).
struct SceneVariety {
  double variety = 0;             // the scenario's
  int attempt = 0;                // draws rejected before this one (object out of view)
  double applied = 0;             // variety used: the scenario's, scaled down after many rejections
  // Background.
  std::vector<std::string> plane_textures;  // per environment plane: what it shows ("built-in" = unchanged)
  std::vector<float> plane_gains;           // per plane: brightness factor of its tint
  ColorBgr background_bgr = ColorBgr::Zero();
  // Light.
  double light_azimuth_deg = 0, light_elevation_deg = 0;
  double light_ambient = 0, light_diffuse = 0;  // including the gain
  double light_gain = 1;
  double light_drift = 0, light_drift_period_s = 10;  // relative amplitude of a slow sine
  // The object's look.
  double albedo_scale = 1;                 // after the contrast guard
  ColorBgr tint_bgr = ColorBgr::Ones();
  std::uint64_t print_seed = 0;            // 0: the built-in prints
  double contrast = 0, builtin_contrast = 0;  // object against background (mean luminance, Michelson)
  bool contrast_raised = false;            // the drawn albedo was moved to keep the minimum contrast
  // Placement.
  double object_yaw_deg = 0;
  Eigen::Vector2d object_offset_m = Eigen::Vector2d::Zero();
  // Camera path.
  Eigen::Vector3d start_world = Eigen::Vector3d::Zero();
  double heading_deg = 0;
  Eigen::Vector3d aim_shift_m = Eigen::Vector3d::Zero();
  double speed_scale = 1, motion_scale = 1, timing_scale = 1;
  std::uint64_t path_seed = 1;             // seed of the walking bursts / hand-held sway sines
  // Occluders.
  double occluder_time_shift_s = 0;
  Eigen::Vector3d occluder_shift_m = Eigen::Vector3d::Zero();
  bool pole = false;
  double pole_mid_s = 0, pole_diameter_m = 0;
  int covers = 0;
  // The object stays in view: the smallest distance of its projected centre from the image
  // border over all frames (pixels; negative = outside).
  double min_border_px = 0;
};

// A scenario's scene as it runs and the scenario with the drawn changes applied (camera path,
// light keys, occluder keys); for variety 0 and no covers, exactly make_scene(s.scene) and s.
struct ScenarioScene {
  Scene scene;
  Scenario scenario;
  SceneVariety drawn;
};

// Draws (deterministically from seed and variety) and applies. Errors: the scene's (unknown
// name, unreadable photo) or the camera file's.
std::expected<ScenarioScene, std::string> make_scenario_scene(const Scenario& scenario);

// Smallest distance (pixels) of the projected object centre (the scene's view target) from the
// image border over every frame of the scenario (or only the frames marked in `frames`);
// negative when it leaves the image or goes behind the camera. The rule a drawn scene must
// pass (>= kMinBorderPx) in every frame where the built-in scene keeps the object in view: a
// scenario may take the object out of view on purpose (late_entry, stumble).
double object_view_margin_px(const Scenario& scenario, const Scene& scene, const vision::Camera& camera,
                             const std::vector<unsigned char>* frames = nullptr);
inline constexpr double kMinBorderPx = 24;
// Per frame: the object centre lies at least kMinBorderPx inside the image.
std::vector<unsigned char> frames_in_view(const Scenario& scenario, const Scene& scene, const vision::Camera& camera);

// The draws as a JSON object (no trailing newline), each line prefixed by `indent`.
std::string to_json(const SceneVariety& drawn, const std::string& indent);

}  // namespace epichead::sim
