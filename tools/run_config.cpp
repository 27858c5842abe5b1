#include "run_config.h"

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace epichead::tools {

namespace fs = std::filesystem;

std::expected<RunConfig, std::string> read_run_config(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::unexpected(path + ": cannot open");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(path + ": not valid JSON: " + e.what());
  }
  const fs::path base = fs::path(path).parent_path();
  auto resolve = [&](const std::string& p) { return fs::path(p).is_absolute() ? p : (base / p).string(); };
  RunConfig c;
  try {
    for (const char* key : {"model", "camera_calibration", "init_pose"})
      if (!j.contains(key) || !j[key].is_string()) return std::unexpected(path + ": missing string field '" + key + "'");
    c.model = resolve(j["model"].get<std::string>());
    c.calibration = resolve(j["camera_calibration"].get<std::string>());
    c.init_pose = resolve(j["init_pose"].get<std::string>());
    c.out = resolve(j.value("out", c.out));
    c.mode = j.value("mode", c.mode);
    if (j.contains("camera")) {
      const auto& cam = j["camera"];
      c.camera.device = cam.value("device", c.camera.device);
      c.camera.width = cam.value("width", c.camera.width);
      c.camera.height = cam.value("height", c.camera.height);
      c.camera.frame_rate_hz = cam.value("fps", c.camera.frame_rate_hz);
    }
    if (j.contains("can")) c.can.interface = j["can"].value("interface", c.can.interface);
    if (j.contains("head")) {
      const auto& h = j["head"];
      c.backlash.pan_rad = h.value("pan_backlash_rad", c.backlash.pan_rad);
      c.backlash.tilt_rad = h.value("tilt_backlash_rad", c.backlash.tilt_rad);
    }
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(path + ": wrong type: " + e.what());
  }
  return c;
}

}  // namespace epichead::tools
