// The `epichead run --config` JSON reader (tools/run_config.h). Properties: a configuration or
// a one-line error starting with the file's path, never an exception, a crash or undefined
// behaviour (a huge number for an integer key included); numbers within the ranges the reader
// promises.
#include <string>

#include "fuzz_support.h"
#include "run_config.h"

using epichead::fuzz::check;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  const std::string path = scratch.write("robot.json", epichead::fuzz::as_text(data, size));
  std::expected<epichead::tools::RunConfig, std::string> config = std::unexpected(std::string());
  try {
    config = epichead::tools::read_run_config(path);
  } catch (const std::exception& e) {
    epichead::fuzz::fail(std::string("read_run_config threw: ") + e.what());
  }
  if (!config) {
    epichead::fuzz::check_one_line(config.error(), "read_run_config");
    check(config.error().starts_with(path), "the error does not name the file: " + config.error());
    return 0;
  }
  check(!config->model.empty() && !config->calibration.empty(), "a file path is empty");
  // The ranges run_config.h promises (also where a compiler without float-cast-overflow checks
  // let an out-of-range cast through: "width": 1e300 gave INT_MIN).
  const auto& cam = config->camera;
  check(cam.width >= 1 && cam.width <= 65535 && cam.height >= 1 && cam.height <= 65535, "image size out of range");
  check(cam.frame_rate_hz >= 0 && cam.frame_rate_hz <= 1e6, "frame rate out of range");
  const auto& backlash = config->backlash;
  check(backlash.pan_rad >= 0 && backlash.pan_rad <= 1 && backlash.tilt_rad >= 0 && backlash.tilt_rad <= 1,
        "backlash out of range");
  const auto& g = config->gains;
  for (const auto& gain : {g.stabilise_gain_per_s, g.fixate_gain_per_s, g.fixate_max_rate_radps, g.target_rate_filter_s,
                           g.target_rate_max_radps, g.hold_gain_per_s, g.hold_max_rate_radps, g.rate_lead_s,
                           g.rate_lead_filter_s})
    check(!gain || (*gain >= 0 && *gain <= 1000), "a controller gain out of range");
  return 0;
}
