#pragma once
// A simulator scenario: which scene, how the camera moves, lighting, noise, occluders, IMU and
// how many frames, read from a small line-based text file (format: sim/scenarios/README.md).
// For closed-loop runs (sim_world.h) also bus timing, head dynamics and injected faults.
#include <cstdint>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "epichead/sim/bus_timing.h"
#include "epichead/sim/fault_plan.h"
#include "epichead/sim/head_dynamics.h"
#include "epichead/sim/head_mount.h"
#include "epichead/sim/imu_model.h"
#include "epichead/sim/trajectory.h"

namespace epichead::sim {

enum class MotionKind { walking, wheeled, handheld };

// Global light level at a time; levels between keys follow a raised-cosine blend.
struct LightKey {
  double t_s = 0;
  double gain = 1;
};

// Position of an occluder (index into Scene::occluders) at a time; linear between keys, held
// before the first and after the last. Its orientation is that of the scene's default path start.
struct OccluderKey {
  int occluder = 0;
  double t_s = 0;
  Eigen::Vector3d position_world = Eigen::Vector3d::Zero();
};

// A window in which a large board slides in front of the camera and hides the tracked object
// completely (key `cover`): the tracker must notice the loss and recover afterwards.
struct CoverWindow {
  static constexpr double kSlideS = 0.3;  // the board slides in before start_s and out after the end
  double start_s = 0;     // the board stands still in front of the camera from here
  double duration_s = 1;  // for this long
  // The board is in front of the camera (sliding or still) at t_s. Whether it hides the whole
  // object is a question of what is drawn: OcclusionTruth (occlusion_truth.h).
  bool board_in_view(double t_s) const { return t_s >= start_s - kSlideS && t_s <= start_s + duration_s + kSlideS; }
};

struct Scenario {
  std::string name;          // file stem (built-in name for built-ins)
  std::string text;          // the file's text, copied into the sequence for reproduction
  std::string scene;         // a scene_library name
  int frames = 0;
  double fps = 30;
  double first_frame_s = 0.2;  // time of frame 0 (the IMU starts at 0)
  std::uint64_t seed = 1;
  std::string camera_path;   // camera.yaml; empty = default_camera()
  std::optional<double> exposure_s;  // unset: the scene's
  std::optional<int> blur_subframes; // unset: the scene's
  int antialias_samples = 4;         // per pixel and sub-frame
  double noise_dn = 1.5;             // sensor noise, grey levels
  double init_error_m = 0.01, init_error_deg = 1.0;  // init.csv perturbation of the frame-0 truth
  std::vector<LightKey> light;       // empty: gain 1
  std::vector<OccluderKey> occluder_keys;  // occluders without keys follow the scene's default path
  std::vector<CoverWindow> covers;         // in file order
  // How far the seed moves the scene away from the one the tracker was tuned on (0..1):
  // background, light, object look and placement, camera path, occluders (scene_variety.h).
  // 0 = the built-in scene exactly.
  double variety = 0;

  MotionKind motion = MotionKind::walking;
  WalkingParams walking;
  WheeledParams wheeled;
  HandheldParams handheld;
  HeadMount mount;
  std::optional<Eigen::Vector3d> aim_world;  // unset: the scene's view target
  double aim_t_s = 0;                        // body pose at which the fixed head angles are aimed
  std::optional<Eigen::Vector2d> head_deg;   // explicit fixed pan, tilt (overrides aim)
  ImuParams imu;

  // Closed loop (sim_world.h); ignored by write_sequence.
  BusTiming bus;
  HeadDynamics head_dynamics;
  double camera_latency_s = 0.010;   // end of exposure -> frame available to the host
  std::vector<FaultWindow> faults;   // in file order

  double frame_time_s(int frame) const { return first_frame_s + frame / fps; }
  double light_gain(double t_s) const;
};

// Parses scenario text; `name` (a path) prefixes messages, relative paths resolve against its
// directory. Every error is "name:line: what".
std::expected<Scenario, std::string> parse_scenario(const std::string& text, const std::string& name);
std::expected<Scenario, std::string> load_scenario(const std::string& path);
// A built-in name (mockup_walk, lampshade, box_clutter, office_pan, can, bowl: sim/scenarios,
// built into the program) or a path to a .scn file.
std::expected<Scenario, std::string> find_scenario(const std::string& name_or_path);
const std::vector<std::string>& builtin_scenario_names();

}  // namespace epichead::sim
