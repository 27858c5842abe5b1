// The `epichead run --config` JSON reader (tools/run_config.h). Properties: a configuration or
// a one-line error starting with the file's path, never an exception, a crash or undefined
// behaviour (a huge number for an integer key included).
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
  check(!config->model.empty() && !config->calibration.empty() && !config->init_pose.empty(), "a file path is empty");
  return 0;
}
