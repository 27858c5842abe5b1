#include "run_config.h"

#include <algorithm>
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

// Each gain: its key, where the file's value goes, the controller's field and the range a sane
// controller stays in (rates in rad/s, times in s).
using Gains = decltype(RunConfig::gains);
using Options = head::HeadControllerOptions;

struct GainField {
  const char* key;
  std::optional<double> Gains::*given;
  double Options::*target;
  double lo, hi;
};

constexpr GainField kGains[] = {
    {"stabilise_gain_per_s", &Gains::stabilise_gain_per_s, &Options::stabilise_gain_per_s, 0, 1000},
    {"fixate_gain_per_s", &Gains::fixate_gain_per_s, &Options::fixate_gain_per_s, 0, 1000},
    {"fixate_max_rate_radps", &Gains::fixate_max_rate_radps, &Options::fixate_max_rate_radps, 0, 50},
    {"target_rate_filter_s", &Gains::target_rate_filter_s, &Options::target_rate_filter_s, 0, 10},
    {"target_rate_max_radps", &Gains::target_rate_max_radps, &Options::target_rate_max_radps, 0, 50},
    {"hold_gain_per_s", &Gains::hold_gain_per_s, &Options::hold_gain_per_s, 0, 1000},
    {"hold_max_rate_radps", &Gains::hold_max_rate_radps, &Options::hold_max_rate_radps, 0, 50},
    {"rate_lead_s", &Gains::rate_lead_s, &Options::rate_lead_s, 0, 1},
    {"rate_lead_filter_s", &Gains::rate_lead_filter_s, &Options::rate_lead_filter_s, 0, 1},
};

const GainField* find_gain(const std::string& key) {
  for (const GainField& f : kGains)
    if (key == f.key) return &f;
  return nullptr;
}

std::string json_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", x);
  return text;
}

std::string json_string(const std::string& s) { return nlohmann::json(s).dump(); }

// The first key of `j` (an object) that run_config_keys() does not list, as "section.key", or
// nothing. A section that is not an object is left to the reader, which says so.
std::optional<std::string> unknown_key(const nlohmann::json& j) {
  const std::vector<RunConfigKey> keys = run_config_keys(head::HeadControllerOptions{});
  auto known = [&](const std::string& name) {
    return std::any_of(keys.begin(), keys.end(), [&](const RunConfigKey& k) { return k.name == name; });
  };
  auto section = [&](const std::string& name) {
    return std::any_of(keys.begin(), keys.end(), [&](const RunConfigKey& k) { return k.name.starts_with(name + "."); });
  };
  for (const auto& [key, value] : j.items()) {
    if (!section(key)) {
      if (!known(key)) return key;
      continue;
    }
    if (!value.is_object()) continue;
    for (const auto& [sub, unused] : value.items())
      if (!known(key + "." + sub)) return key + "." + sub;
  }
  return std::nullopt;
}

}  // namespace

std::vector<RunConfigKey> run_config_keys(const head::HeadControllerOptions& controller) {
  const RunConfig d;  // the defaults of every key but the gains, from the option types
  std::vector<RunConfigKey> keys{
      {"model", "string", "required"},
      {"camera_calibration", "string", "required"},
      {"init_pose", "string", "none"},
      {"template_cache", "string", "none"},
      {"reacquire", "boolean", d.reacquire ? "true" : "false"},
      {"object_up", "array", "none"},
      {"mode", "string", json_string(d.mode)},
      {"out", "string", json_string(d.out)},
      {"camera.device", "string", json_string(d.camera.device)},
      {"camera.width", "integer", std::to_string(d.camera.width)},
      {"camera.height", "integer", std::to_string(d.camera.height)},
      {"camera.fps", "number", json_number(d.camera.frame_rate_hz)},
      {"can.interface", "string", json_string(d.can.interface)},
      {"can.receive_buffer_bytes", "integer", std::to_string(d.can.receive_buffer_bytes)},
      {"can.time_sync_max_round_trip_ms", "number", json_number(d.time_sync_max_round_trip_s * 1e3)},
      {"head.pan_backlash_rad", "number", json_number(d.backlash.pan_rad)},
      {"head.tilt_backlash_rad", "number", json_number(d.backlash.tilt_rad)},
      {"threads.control_cpu", "integer", std::to_string(d.threads.control_cpu)},
      {"threads.vision_cpu", "integer", std::to_string(d.threads.vision_cpu)},
      {"threads.control_priority", "integer", std::to_string(d.threads.control_priority)},
      {"threads.vision_priority", "integer", std::to_string(d.threads.vision_priority)},
      {"threads.lock_memory", "boolean", d.threads.lock_memory ? "true" : "false"},
  };
  for (const GainField& f : kGains)
    keys.push_back({std::string("controller.") + f.key, "number", json_number(controller.*f.target)});
  return keys;
}

head::HeadControllerOptions controller_options(const RunConfig& config, head::HeadControllerOptions options) {
  options.backlash = config.backlash;
  for (const GainField& f : kGains)
    if (const auto& v = config.gains.*f.given) options.*f.target = *v;
  return options;
}

std::string run_config_help(const head::HeadControllerOptions& controller) {
  const RunConfig d;  // the defaults of every key but the gains, from the option types
  std::string gains;
  for (const GainField& f : kGains) {
    char item[96];
    std::snprintf(item, sizeof item, "%s\"%s\": %g", gains.empty() ? "" : ",\n                    ", f.key,
                  controller.*f.target);
    gains += item;
  }
  char devices[512];
  std::snprintf(devices, sizeof devices,
                "    \"camera\": { \"device\": \"%s\", \"width\": %d, \"height\": %d, \"fps\": %g },\n"
                "    \"can\": { \"interface\": \"%s\", \"receive_buffer_bytes\": %d,\n"
                "             \"time_sync_max_round_trip_ms\": %g },\n"
                "    \"head\": { \"pan_backlash_rad\": %g, \"tilt_backlash_rad\": %g },\n"
                "    \"threads\": { \"control_cpu\": %d, \"vision_cpu\": %d, \"control_priority\": %d,\n"
                "                 \"vision_priority\": %d, \"lock_memory\": %s },\n",
                d.camera.device.c_str(), d.camera.width, d.camera.height, d.camera.frame_rate_hz, d.can.interface.c_str(),
                d.can.receive_buffer_bytes, d.time_sync_max_round_trip_s * 1e3,
                d.backlash.pan_rad, d.backlash.tilt_rad, d.threads.control_cpu, d.threads.vision_cpu,
                d.threads.control_priority, d.threads.vision_priority, d.threads.lock_memory ? "true" : "false");
  return "The configuration (JSON; relative paths from its folder; every key but model and\n"
         "camera_calibration is optional, with the default shown):\n"
         "  { \"model\": \"teabox/model.cao\", \"camera_calibration\": \"teabox/camera.yaml\",\n"
         "    \"init_pose\": \"teabox/init.csv\", \"template_cache\": \"~/.cache/epichead\",\n"
         "    \"reacquire\": true, \"object_up\": [0, 0, 1],\n" +
         std::string(devices) + "    \"controller\": { " + gains + " },\n    \"mode\": \"" + d.mode +
         "\",\n    \"out\": \"" + d.out +
         "\" }\n"
         "fps 0: the driver's current rate. receive_buffer_bytes: the kernel's CAN receive queue (0: its\n"
         "default; without CAP_NET_ADMIN capped at net.core.rmem_max). time_sync_max_round_trip_ms: longer\n"
         "time-sync round trips with the IMU are ignored (at most 60; raise it only on a loaded machine). Backlash: the gear's dead band per joint (0: none). The\n"
         "controller's gains are explained in docs/head.md; mode is fixate, stabilise or hold.\n"
         "threads: the CPU each thread is pinned to (-1: any) and its SCHED_FIFO priority (1..99; 0: normal\n"
         "scheduling); lock_memory locks the process in RAM. A refusal (no CAP_SYS_NICE or rtprio limit)\n"
         "is reported in summary.json and the run goes on with normal scheduling (docs/head.md).\n"
         "Without init_pose the object is detected from the model (templates cached in template_cache;\n"
         "by default $EPICHEAD_CACHE_DIR, else $XDG_CACHE_HOME/epichead, else ~/.cache/epichead;\n"
         "built once, with progress when stderr is a terminal); with reacquire it is detected again after a loss\n"
         "(docs/detection.md). reacquire false with an init_pose builds no templates.\n"
         "object_up (none by default): the object's up in its model's frame when it stands on its base;\n"
         "poses are then checked against gravity from the start instead of the down being learnt from them,\n"
         "and detection searches upright views only (docs/fusion.md).\n"
         "A key not listed here is an error. Every key with its unit and meaning: docs/run_config.md.\n";
}

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
    for (const char* key : {"model", "camera_calibration"})
      if (!j.contains(key) || !j[key].is_string()) return std::unexpected(path + ": missing string field '" + key + "'");
    // Before any default is taken: a misspelt key would otherwise leave its default in force unseen.
    if (const auto key = unknown_key(j))
      return std::unexpected(path + ": unknown key " +
                             nlohmann::json(*key).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) +
                             " (docs/run_config.md lists the keys)");
    c.model = resolve(j["model"].get<std::string>());
    c.calibration = resolve(j["camera_calibration"].get<std::string>());
    // Without a start pose the loop detects the object (vision/detector.h).
    for (const char* key : {"init_pose", "template_cache"})
      if (j.contains(key) && !j[key].is_string()) return std::unexpected(path + ": '" + key + "' must be a string (a path)");
    if (j.contains("init_pose")) c.init_pose = resolve(j["init_pose"].get<std::string>());
    if (j.contains("template_cache")) c.template_cache = resolve(j["template_cache"].get<std::string>());
    if (j.contains("reacquire")) {
      if (!j["reacquire"].is_boolean()) return std::unexpected(path + ": 'reacquire' must be true or false");
      c.reacquire = j["reacquire"].get<bool>();
    }
    if (j.contains("object_up")) {
      const auto& up = j["object_up"];
      bool ok = up.is_array() && up.size() == 3;
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (std::size_t i = 0; ok && i < 3; ++i) {
        ok = up[i].is_number();
        if (ok) v[static_cast<Eigen::Index>(i)] = up[i].get<double>();
      }
      if (!ok || !v.allFinite() || !(v.norm() > 1e-9))
        return std::unexpected(path + ": 'object_up' must be [x, y, z], a non-zero direction in the model's frame");
      c.object_up = v.normalized();
    }
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
    if (j.contains("can")) {
      const auto& can = j["can"];
      if (!can.is_object()) return fail("can must be an object");
      c.can.interface = can.value("interface", c.can.interface);
      const auto queue = number(can, "can", "receive_buffer_bytes", c.can.receive_buffer_bytes, 0, 1 << 30, true);
      if (!queue) return fail(queue.error());
      c.can.receive_buffer_bytes = static_cast<int>(*queue);
      const auto round_trip = number(can, "can", "time_sync_max_round_trip_ms", c.time_sync_max_round_trip_s * 1e3, 0.1,
                                     head::kMaxClockSyncRoundTrip_s * 1e3, false);
      if (!round_trip) return fail(round_trip.error());
      c.time_sync_max_round_trip_s = *round_trip * 1e-3;
    }
    if (j.contains("head")) {
      const auto& h = j["head"];
      if (!h.is_object()) return fail("head must be an object");
      const auto pan = number(h, "head", "pan_backlash_rad", c.backlash.pan_rad, 0, 1, false);
      if (!pan) return fail(pan.error());
      const auto tilt = number(h, "head", "tilt_backlash_rad", c.backlash.tilt_rad, 0, 1, false);
      if (!tilt) return fail(tilt.error());
      c.backlash.pan_rad = *pan;
      c.backlash.tilt_rad = *tilt;
    }
    if (j.contains("threads")) {
      const auto& t = j["threads"];
      if (!t.is_object()) return fail("threads must be an object");
      struct IntKey { const char* key; int* target; double lo, hi; };
      const IntKey keys[] = {{"control_cpu", &c.threads.control_cpu, -1, 1023},
                             {"vision_cpu", &c.threads.vision_cpu, -1, 1023},
                             {"control_priority", &c.threads.control_priority, 0, 99},
                             {"vision_priority", &c.threads.vision_priority, 0, 99}};
      for (const auto& [key, value] : t.items()) {
        if (key == "lock_memory") {
          if (!value.is_boolean()) return fail("threads.lock_memory must be true or false");
          c.threads.lock_memory = value.get<bool>();
          continue;
        }
        const IntKey* k = nullptr;
        for (const IntKey& candidate : keys)
          if (key == candidate.key) k = &candidate;
        if (!k) return fail("threads." + key + " is not a key of threads (epichead run --help lists them)");
        const auto v = number(t, "threads", k->key, *k->target, k->lo, k->hi, true);
        if (!v) return fail(v.error());
        *k->target = static_cast<int>(*v);
      }
      if (c.threads.vision_priority > 0 && c.threads.vision_priority >= c.threads.control_priority)
        return fail("threads.vision_priority must be below control_priority: vision must never preempt the control loop");
    }
    if (j.contains("controller")) {
      const auto& g = j["controller"];
      if (!g.is_object()) return fail("controller must be an object");
      for (const auto& [key, value] : g.items()) {
        const GainField* field = find_gain(key);
        if (!field) return fail("controller." + key + " is not a controller gain (epichead run --help lists them)");
        const auto v = number(g, "controller", field->key, 0, field->lo, field->hi, false);
        if (!v) return fail(v.error());
        c.gains.*field->given = *v;
      }
    }
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(path + ": wrong type: " + e.what());
  }
  return c;
}

}  // namespace epichead::tools
