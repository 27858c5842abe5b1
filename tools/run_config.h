#pragma once
// The configuration of `epichead run --config FILE`: the onboard loop on real devices. JSON:
//
//   { "model": "teabox/model.cao", "camera_calibration": "teabox/camera.yaml",
//     "init_pose": "teabox/init.csv",              // where tracking starts (cMo)
//     "camera": { "device": "/dev/video0", "width": 640, "height": 480,
//                 "fps": 0 },                      // 0: the driver's current frame rate
//     "can": { "interface": "can0" },
//     "head": { "pan_backlash_rad": 0,             // the gear's dead band per joint, as measured
//               "tilt_backlash_rad": 0 },          // (docs/head.md); 0: no compensation
//     "controller": { "stabilise_gain_per_s": 60,   // optical-axis angle error -> camera rate
//                     "fixate_gain_per_s": 5,       // target angle error -> camera rate
//                     "fixate_max_rate_radps": 1.5, // how fast fixation itself may turn the camera
//                     "target_rate_filter_s": 0.15, // low-pass of the target direction's rate
//                     "target_rate_max_radps": 1.0, // bound on that rate's feed-forward
//                     "hold_gain_per_s": 10,        // joint angle error -> joint rate (hold, park)
//                     "hold_max_rate_radps": 2.0,
//                     "rate_lead_s": 0,             // body-rate prediction; 0: off (docs/head.md)
//                     "rate_lead_filter_s": 0.004 },
//     "mode": "fixate",                            // fixate | stabilise | hold
//     "out": "run-out" }                           // bus.log and diagnostics.jsonl go here
//
// Relative paths are taken from the configuration file's folder. Every key but the three files
// has the default shown. A library of its own (not only in cmd_run.cpp) so the fuzz target
// tests/fuzz/fuzz_run_config.cpp links the same reader the program uses.
#include <expected>
#include <string>

#include <optional>

#include "epichead/head/head_controller.h"
#include "epichead/hw/socketcan_bus.h"
#include "epichead/hw/v4l2_camera.h"

namespace epichead::tools {

struct RunConfig {
  std::string model, calibration, init_pose, out = "run-out", mode = "fixate";
  hw::V4l2CameraOptions camera;
  hw::SocketCanOptions can;
  head::JointBacklash backlash;
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
