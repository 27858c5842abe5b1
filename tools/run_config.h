#pragma once
// The configuration of `epichead run --config FILE`: the onboard loop on real devices, as JSON:
// the model, calibration and start pose files, the camera device, the CAN interface, the joints'
// backlash, the controller's gains, the mode and the output folder. The keys with their defaults
// are what run_config_help() prints (`epichead run --help`), made from the option types
// themselves so the text cannot drift from the code. Relative paths are taken from the
// configuration file's folder. A library of its own (not only in cmd_run.cpp) so the fuzz target
// tests/fuzz/fuzz_run_config.cpp links the same reader the program uses.
#include <expected>
#include <optional>
#include <string>

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

// The controller's options with the file's gains and backlash applied.
head::HeadControllerOptions controller_options(const RunConfig& config, head::HeadControllerOptions defaults);

// The keys with the defaults of `controller`, as `epichead run --help` prints them.
std::string run_config_help(const head::HeadControllerOptions& controller);

// Reads the JSON file at `path`; the three file paths are resolved against its folder. Numbers
// are checked: camera width and height whole numbers 1..65535, fps 0..1e6, backlashes 0..1 rad,
// the controller's gains within their ranges. Errors are one line starting with the path.
std::expected<RunConfig, std::string> read_run_config(const std::string& path);

}  // namespace epichead::tools
