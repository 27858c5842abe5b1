#pragma once
// The configuration of `epichead run --config FILE`: the onboard loop on real devices, as JSON:
// the model, calibration and start pose files, the camera device, the CAN interface, the joints'
// backlash, the controller's gains, the mode and the output folder. Every key with its type, unit,
// default and meaning: docs/run_config.md (a test checks its keys and defaults against
// run_config_keys()). The keys with their defaults are also what run_config_help() prints
// (`epichead run --help`), made from the option types themselves so the text cannot drift from
// the code. A key the reader does not know is an error, never ignored. Relative paths are taken from the
// configuration file's folder. A library of its own (not only in cmd_run.cpp) so the fuzz target
// tests/fuzz/fuzz_run_config.cpp links the same reader the program uses.
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "epichead/head/head_controller.h"
#include "epichead/head/realtime_options.h"
#include "epichead/head/device_clock_sync.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/hw/v4l2_camera.h"

namespace epichead::tools {

struct RunConfig {
  std::string model, calibration, out = "run-out", mode = "fixate";
  std::string init_pose;       // empty: the object is detected
  std::string template_cache;  // empty: vision::default_template_cache_dir()
  bool reacquire = true;       // detection after a loss (needs the templates)
  std::optional<Eigen::Vector3d> object_up;  // unit, model frame: the object stands on its base this way up
  hw::V4l2CameraOptions camera;
  hw::SocketCanOptions can;
  double time_sync_max_round_trip_s = head::ClockSyncOptions{}.max_round_trip_s;  // "can": time_sync_max_round_trip_ms
  head::JointBacklash backlash;
  head::RealtimeOptions threads;  // "threads": CPUs and real-time priorities of the control and vision threads
  // The controller's gains the file gives; the others keep HeadControllerOptions' defaults.
  struct {
    std::optional<double> stabilise_gain_per_s, fixate_gain_per_s, fixate_max_rate_radps, target_rate_filter_s,
        target_rate_max_radps, hold_gain_per_s, hold_max_rate_radps, rate_lead_s, rate_lead_filter_s;
  } gains;
};

// One key of the configuration file: its dotted name ("camera.width"), its JSON type (string,
// integer, number, boolean) and its default as JSON text ("required": the file must give it;
// "none": absent, that feature is off or found otherwise — docs/run_config.md says how).
struct RunConfigKey {
  std::string name, type, default_json;
};

// Every key the reader knows, in the order docs/run_config.md lists them; the gains' defaults
// are `controller`'s.
std::vector<RunConfigKey> run_config_keys(const head::HeadControllerOptions& controller);

// The controller's options with the file's gains and backlash applied.
head::HeadControllerOptions controller_options(const RunConfig& config, head::HeadControllerOptions defaults);

// The keys with the defaults of `controller`, as `epichead run --help` prints them.
std::string run_config_help(const head::HeadControllerOptions& controller);

// Reads the JSON file at `path`; the three file paths are resolved against its folder. Numbers
// are checked: camera width and height whole numbers 1..65535, fps 0..1e6, backlashes 0..1 rad,
// the controller's gains within their ranges. A key not in run_config_keys() is an error naming
// it (a typo must not fall back to the default silently). Errors are one line starting with the path.
std::expected<RunConfig, std::string> read_run_config(const std::string& path);

}  // namespace epichead::tools
