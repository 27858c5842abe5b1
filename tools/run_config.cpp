#include "run_config.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

namespace epichead::tools {

namespace fs = std::filesystem;

namespace {

// A number field of an object, or `fallback` when the key is absent. Checked before nlohmann
// converts it: its get<int>() of a double out of int's range (a "width": 1e300) is undefined
// behaviour, and it would silently truncate 640.5. The error names the field and the range.
std::expected<double, std::string> number(const nlohmann::json& object, const char* object_name, const char* key,
                                          double fallback, double lo, double hi, bool whole) {
  if (!object.contains(key)) return fallback;
  const nlohmann::json& v = object[key];
  const std::string name = std::string(object_name) + "." + key;
  char range[96];
  std::snprintf(range, sizeof range, "a %s from %g to %g", whole ? "whole number" : "number", lo, hi);
  if (!v.is_number()) return std::unexpected(name + " must be " + std::string(range));
  const double x = v.get<double>();
  if (!(x >= lo && x <= hi) || (whole && x != static_cast<double>(static_cast<long long>(x))))
    return std::unexpected(name + " must be " + range + ", got " + v.dump());
  return x;
}

}  // namespace

const char* const kRunConfigHelp = R"(The configuration (JSON; relative paths from its folder; every key but the three files has
the default shown):
  { "model": "teabox/model.cao", "camera_calibration": "teabox/camera.yaml",
    "init_pose": "teabox/init.csv",
    "camera": { "device": "/dev/video0", "width": 640, "height": 480, "fps": 0 },
    "can": { "interface": "can0" },
    "head": { "pan_backlash_rad": 0, "tilt_backlash_rad": 0 },
    "controller": { "stabilise_gain_per_s": 60, "fixate_gain_per_s": 5,
                    "fixate_max_rate_radps": 1.5, "target_rate_filter_s": 0.15,
                    "target_rate_max_radps": 1.0, "hold_gain_per_s": 10,
                    "hold_max_rate_radps": 2.0, "rate_lead_s": 0, "rate_lead_filter_s": 0.004 },
    "mode": "fixate",
    "out": "run-out" }
fps 0: the driver's current rate. Backlash: the gear's dead band per joint (0: none). The
controller's gains are explained in docs/head.md; mode is fixate, stabilise or hold.)";

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
    auto fail = [&](const std::string& what) { return std::unexpected(path + ": " + what); };
    if (j.contains("camera")) {
      const auto& cam = j["camera"];
      if (!cam.is_object()) return fail("camera must be an object");
      c.camera.device = cam.value("device", c.camera.device);
      const auto width = number(cam, "camera", "width", c.camera.width, 1, 65535, true);
      if (!width) return fail(width.error());
      const auto height = number(cam, "camera", "height", c.camera.height, 1, 65535, true);
      if (!height) return fail(height.error());
      const auto fps = number(cam, "camera", "fps", c.camera.frame_rate_hz, 0, 1e6, false);
      if (!fps) return fail(fps.error());
      c.camera.width = static_cast<int>(*width);
      c.camera.height = static_cast<int>(*height);
      c.camera.frame_rate_hz = *fps;
    }
    if (j.contains("can")) c.can.interface = j["can"].value("interface", c.can.interface);
    if (j.contains("head")) {
      const auto& h = j["head"];
      if (!h.is_object()) return fail("head must be an object");
      const auto pan = number(h, "head", "pan_backlash_rad", c.controller.backlash.pan_rad, 0, 1, false);
      if (!pan) return fail(pan.error());
      const auto tilt = number(h, "head", "tilt_backlash_rad", c.controller.backlash.tilt_rad, 0, 1, false);
      if (!tilt) return fail(tilt.error());
      c.controller.backlash.pan_rad = *pan;
      c.controller.backlash.tilt_rad = *tilt;
    }
    if (j.contains("controller")) {
      const auto& g = j["controller"];
      if (!g.is_object()) return fail("controller must be an object");
      head::HeadControllerOptions& o = c.controller;
      // Each gain, its field and the range a sane controller stays in (rates in rad/s, times in s).
      const struct {
        const char* key;
        double* field;
        double lo, hi;
      } gains[] = {{"stabilise_gain_per_s", &o.stabilise_gain_per_s, 0, 1000},
                   {"fixate_gain_per_s", &o.fixate_gain_per_s, 0, 1000},
                   {"fixate_max_rate_radps", &o.fixate_max_rate_radps, 0, 50},
                   {"target_rate_filter_s", &o.target_rate_filter_s, 0, 10},
                   {"target_rate_max_radps", &o.target_rate_max_radps, 0, 50},
                   {"hold_gain_per_s", &o.hold_gain_per_s, 0, 1000},
                   {"hold_max_rate_radps", &o.hold_max_rate_radps, 0, 50},
                   {"rate_lead_s", &o.rate_lead_s, 0, 1},
                   {"rate_lead_filter_s", &o.rate_lead_filter_s, 0, 1}};
      for (const auto& gain : gains) {
        const auto v = number(g, "controller", gain.key, *gain.field, gain.lo, gain.hi, false);
        if (!v) return fail(v.error());
        *gain.field = *v;
      }
      for (const auto& [key, value] : g.items()) {
        bool known = false;
        for (const auto& gain : gains) known = known || key == gain.key;
        if (!known) return fail("controller." + key + " is not a controller gain (docs: epichead run --help)");
      }
    }
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(path + ": wrong type: " + e.what());
  }
  return c;
}

}  // namespace epichead::tools
