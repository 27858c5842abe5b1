// The scenario file parser: a table of keys, each with its value count, whether it may repeat,
// which motion kind it belongs to and a handler that checks and stores its values; errors name
// file:line and the key (scenarios/README.md, docs/reliability.md).
#include "epichead/sim/scenario.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "epichead/sim/scene_library.h"

namespace epichead::sim {
namespace {

constexpr double deg = std::numbers::pi / 180.0;
constexpr double inf = std::numeric_limits<double>::infinity();

using Args = std::vector<std::string>;
using Status = std::expected<void, std::string>;

// One key's rule: how many values, whether it may repeat, which motion kind it belongs to.
struct Rule {
  std::size_t min_args = 1, max_args = 1;
  bool repeatable = false;
  std::optional<MotionKind> kind;
  std::function<Status(const Args&)> apply;
};

class Parser {
 public:
  Parser(std::string name) : name_(std::move(name)) {
    base_dir_ = std::filesystem::path(name_).parent_path().string();
    if (base_dir_.empty()) base_dir_ = ".";
    define_rules();
  }

  std::expected<Scenario, std::string> parse(const std::string& text) {
    sc_.text = text;
    sc_.name = std::filesystem::path(name_).stem().string();
    std::istringstream in(text);
    std::string raw;
    std::set<std::string> seen;
    while (std::getline(in, raw)) {
      ++line_;
      if (const auto hash = raw.find('#'); hash != std::string::npos) raw.resize(hash);
      std::istringstream words(raw);
      std::string key;
      if (!(words >> key)) continue;
      Args args;
      for (std::string w; words >> w;) args.push_back(w);
      key_ = key;
      const auto it = rules_.find(key);
      if (it == rules_.end()) return std::unexpected(where() + "unknown key '" + key + "'");
      const Rule& r = it->second;
      if (!r.repeatable && !seen.insert(key).second) return std::unexpected(where() + "'" + key + "' given twice");
      if (args.size() < r.min_args || args.size() > r.max_args) {
        const std::string n = r.min_args == r.max_args ? std::to_string(r.min_args)
                                                        : std::to_string(r.min_args) + " to " + std::to_string(r.max_args);
        return std::unexpected(where() + "'" + key + "' takes " + n + " value(s), got " + std::to_string(args.size()));
      }
      if (r.kind) {
        if (!motion_seen_) return std::unexpected(where() + "'" + key + "' needs a 'motion' line before it");
        if (*r.kind != sc_.motion)
          return std::unexpected(where() + "'" + key + "' does not apply to motion " + motion_name(sc_.motion));
      }
      if (auto ok = r.apply(args); !ok) return std::unexpected(ok.error());
    }
    for (const char* required : {"scene", "frames", "motion"}) {
      if (!seen.count(required))
        return std::unexpected(name_ + ":" + std::to_string(std::max(line_, 1)) + ": missing required key '" + required + "'");
    }
    if (sc_.motion == MotionKind::walking && sc_.walking.burst_s >= sc_.walking.step_period_s) {
      return std::unexpected(name_ + ":" + std::to_string(burst_line_) + ": burst_s must be shorter than step_period_s");
    }
    return sc_;
  }

 private:
  static std::string motion_name(MotionKind k) {
    switch (k) {
      case MotionKind::walking: return "walking";
      case MotionKind::wheeled: return "wheeled";
      case MotionKind::handheld: return "handheld";
    }
    return "?";
  }

  std::string where() const { return name_ + ":" + std::to_string(line_) + ": "; }

  std::expected<double, std::string> num(const std::string& s, double lo, double hi) const {
    double v = 0;
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, v);
    if (ec != std::errc() || ptr != end || !std::isfinite(v))
      return std::unexpected(where() + "'" + key_ + "': '" + s + "' is not a number");
    if (v < lo || v > hi) {
      std::ostringstream o;
      o << where() << "'" << key_ << "': " << s << " is out of range [" << lo << ", " << hi << "]";
      return std::unexpected(o.str());
    }
    return v;
  }

  std::expected<long long, std::string> integer(const std::string& s, long long lo, long long hi) const {
    long long v = 0;
    const char* end = s.data() + s.size();
    const auto [ptr, ec] = std::from_chars(s.data(), end, v);
    if (ec != std::errc() || ptr != end) return std::unexpected(where() + "'" + key_ + "': '" + s + "' is not an integer");
    if (v < lo || v > hi)
      return std::unexpected(where() + "'" + key_ + "': " + s + " is out of range [" + std::to_string(lo) + ", " +
                             std::to_string(hi) + "]");
    return v;
  }

  // Rules for keys with fixed-count numeric values: values land in `out` after range checks.
  void numbers(const std::string& key, std::vector<double*> out, double lo, double hi,
               std::optional<MotionKind> kind = std::nullopt, double scale = 1.0) {
    Rule r;
    r.min_args = r.max_args = out.size();
    r.kind = kind;
    r.apply = [this, out, lo, hi, scale](const Args& a) -> Status {
      for (std::size_t i = 0; i < out.size(); ++i) {
        auto v = num(a[i], lo, hi);
        if (!v) return std::unexpected(v.error());
        *out[i] = *v * scale;
      }
      return {};
    };
    rules_[key] = std::move(r);
  }
  void vec3(const std::string& key, Eigen::Vector3d* out, double lo, double hi, std::optional<MotionKind> kind = std::nullopt,
            double scale = 1.0) {
    numbers(key, {&out->x(), &out->y(), &out->z()}, lo, hi, kind, scale);
  }

  // Every key's rule, in the sections of scenarios/README.md.
  void define_rules() {
    define_general_rules();
    define_timeline_rules();
    define_path_rules();
    define_walking_rules();
    define_wheeled_rules();
    define_handheld_rules();
    define_imu_rules();
    define_closed_loop_rules();
  }

  // General: the scene, frames and their timing, the seed, the camera and its rendering, the
  // initial error, the variety.
  void define_general_rules() {
    rules_["scene"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      const auto& names = scene_names();
      for (const auto& n : names) if (n == a[0]) { sc_.scene = a[0]; return {}; }
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      return std::unexpected(where() + "unknown scene '" + a[0] + "' (known: " + known + ")");
    }};
    rules_["frames"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      auto v = integer(a[0], 1, 1000000);
      if (!v) return std::unexpected(v.error());
      sc_.frames = static_cast<int>(*v);
      return {};
    }};
    numbers("fps", {&sc_.fps}, 0.1, 1000);
    numbers("first_frame_s", {&sc_.first_frame_s}, 0, 3600);
    rules_["seed"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      std::uint64_t v = 0;
      const char* end = a[0].data() + a[0].size();
      const auto [ptr, ec] = std::from_chars(a[0].data(), end, v);
      if (ec != std::errc() || ptr != end) return std::unexpected(where() + "'seed': '" + a[0] + "' is not an unsigned integer");
      sc_.seed = v;
      return {};
    }};
    rules_["camera"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      if (a[0] == "default") { sc_.camera_path.clear(); return {}; }
      const std::filesystem::path p(a[0]);
      sc_.camera_path = p.is_absolute() ? p.string() : (std::filesystem::path(base_dir_) / p).lexically_normal().string();
      if (!std::filesystem::exists(sc_.camera_path)) return std::unexpected(where() + "camera file '" + sc_.camera_path + "' does not exist");
      return {};
    }};
    rules_["exposure_s"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      auto v = num(a[0], 0, 1);
      if (!v) return std::unexpected(v.error());
      sc_.exposure_s = *v;
      return {};
    }};
    rules_["blur_subframes"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      auto v = integer(a[0], 1, 64);
      if (!v) return std::unexpected(v.error());
      sc_.blur_subframes = static_cast<int>(*v);
      return {};
    }};
    rules_["antialias"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      auto v = integer(a[0], 1, 64);
      if (!v) return std::unexpected(v.error());
      sc_.antialias_samples = static_cast<int>(*v);
      return {};
    }};
    numbers("noise_dn", {&sc_.noise_dn}, 0, 100);
    numbers("init_error", {&sc_.init_error_m, &sc_.init_error_deg}, 0, 90);
    numbers("variety", {&sc_.variety}, 0, 1);
  }

  // Keys over time: light levels, occluder positions, cover windows.
  void define_timeline_rules() {
    rules_["light"] = {2, 2, true, std::nullopt, [this](const Args& a) -> Status {
      auto t = num(a[0], 0, 1e6);
      if (!t) return std::unexpected(t.error());
      auto g = num(a[1], 0, 100);
      if (!g) return std::unexpected(g.error());
      if (!sc_.light.empty() && *t <= sc_.light.back().t_s)
        return std::unexpected(where() + "'light': times must increase");
      sc_.light.push_back({*t, *g});
      return {};
    }};
    rules_["occluder"] = {5, 5, true, std::nullopt, [this](const Args& a) -> Status {
      auto i = integer(a[0], 0, 99);
      if (!i) return std::unexpected(i.error());
      OccluderKey k;
      k.occluder = static_cast<int>(*i);
      auto t = num(a[1], 0, 1e6);
      if (!t) return std::unexpected(t.error());
      k.t_s = *t;
      for (int j = 0; j < 3; ++j) {
        auto v = num(a[2 + j], -1000, 1000);
        if (!v) return std::unexpected(v.error());
        k.position_world[j] = *v;
      }
      for (auto it = sc_.occluder_keys.rbegin(); it != sc_.occluder_keys.rend(); ++it) {
        if (it->occluder != k.occluder) continue;
        if (k.t_s <= it->t_s) return std::unexpected(where() + "'occluder': times must increase per occluder");
        break;
      }
      sc_.occluder_keys.push_back(k);
      return {};
    }};
    rules_["cover"] = {2, 2, true, std::nullopt, [this](const Args& a) -> Status {
      auto t = num(a[0], 0, 1e6);
      if (!t) return std::unexpected(t.error());
      auto d = num(a[1], 0.05, 1e6);
      if (!d) return std::unexpected(d.error());
      if (!sc_.covers.empty() && *t < sc_.covers.back().start_s + sc_.covers.back().duration_s)
        return std::unexpected(where() + "'cover': windows must not overlap and must be in time order");
      sc_.covers.push_back({*t, *d});
      return {};
    }};
  }

  // Motion and head, every kind: the motion kind, where the body starts and faces, where the head
  // looks, the head's geometry.
  void define_path_rules() {
    rules_["motion"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      if (a[0] == "walking") sc_.motion = MotionKind::walking;
      else if (a[0] == "wheeled") sc_.motion = MotionKind::wheeled;
      else if (a[0] == "handheld") sc_.motion = MotionKind::handheld;
      else return std::unexpected(where() + "unknown motion kind '" + a[0] + "' (known: walking, wheeled, handheld)");
      motion_seen_ = true;
      return {};
    }};
    // start and heading apply to every kind; they go to the chosen kind's parameters.
    rules_["start"] = {3, 3, false, std::nullopt, [this](const Args& a) -> Status {
      if (!motion_seen_) return std::unexpected(where() + "'start' needs a 'motion' line before it");
      Eigen::Vector3d p;
      for (int j = 0; j < 3; ++j) {
        auto v = num(a[j], -1000, 1000);
        if (!v) return std::unexpected(v.error());
        p[j] = *v;
      }
      sc_.walking.start_world = sc_.wheeled.start_world = sc_.handheld.start_world = p;
      return {};
    }};
    rules_["heading_deg"] = {1, 1, false, std::nullopt, [this](const Args& a) -> Status {
      if (!motion_seen_) return std::unexpected(where() + "'heading_deg' needs a 'motion' line before it");
      auto v = num(a[0], -360, 360);
      if (!v) return std::unexpected(v.error());
      sc_.walking.heading_rad = sc_.wheeled.heading_rad = sc_.handheld.heading_rad = *v * deg;
      if (!drive_heading_set_) sc_.wheeled.drive_heading_rad = *v * deg;
      return {};
    }};
    rules_["aim"] = {3, 3, false, std::nullopt, [this](const Args& a) -> Status {
      Eigen::Vector3d p;
      for (int j = 0; j < 3; ++j) {
        auto v = num(a[j], -1000, 1000);
        if (!v) return std::unexpected(v.error());
        p[j] = *v;
      }
      sc_.aim_world = p;
      return {};
    }};
    numbers("aim_time_s", {&sc_.aim_t_s}, 0, 1e6);
    rules_["head_deg"] = {2, 2, false, std::nullopt, [this](const Args& a) -> Status {
      auto p = num(a[0], -360, 360);
      if (!p) return std::unexpected(p.error());
      auto t = num(a[1], -90, 90);
      if (!t) return std::unexpected(t.error());
      sc_.head_deg = Eigen::Vector2d(*p, *t);
      return {};
    }};
    vec3("pan_origin_m", &sc_.mount.pan_origin_body, -10, 10);
    vec3("tilt_origin_m", &sc_.mount.tilt_origin_pan, -10, 10);
    vec3("cam_offset_m", &sc_.mount.cam_offset_tilt, -10, 10);
    vec3("cam_misalign_deg", &sc_.mount.cam_misalign_rad, -10, 10, std::nullopt, deg);
  }

  // Walking robot.
  void define_walking_rules() {
    const auto W = MotionKind::walking;
    numbers("speed_mps", {&sc_.walking.speed_mps}, 0, 2, W);
    numbers("surge", {&sc_.walking.surge}, 0, 1, W);
    numbers("step_period_s", {&sc_.walking.step_period_s}, 0.05, 100, W);
    numbers("first_step_s", {&sc_.walking.first_step_s}, 0, 1e6, W);
    rules_["burst_degps"] = {2, 2, false, W, [this](const Args& a) -> Status {
      auto lo = num(a[0], 0, 2000);
      if (!lo) return std::unexpected(lo.error());
      auto hi = num(a[1], *lo, 2000);
      if (!hi) return std::unexpected(hi.error());
      sc_.walking.burst_min_degps = *lo;
      sc_.walking.burst_max_degps = *hi;
      return {};
    }};
    rules_["burst_s"] = {1, 1, false, W, [this](const Args& a) -> Status {
      auto v = num(a[0], 0.01, 100);
      if (!v) return std::unexpected(v.error());
      sc_.walking.burst_s = *v;
      burst_line_ = line_;
      return {};
    }};
    numbers("bob_m", {&sc_.walking.bob_m}, 0, 0.5, W);
    numbers("bob_s", {&sc_.walking.bob_s}, 0.01, 100, W);
    numbers("jerk", {&sc_.walking.jerk}, 0, 20, W);
  }

  // Wheeled robot.
  void define_wheeled_rules() {
    const auto V = MotionKind::wheeled;
    rules_["drive_heading_deg"] = {1, 1, false, V, [this](const Args& a) -> Status {
      auto v = num(a[0], -360, 360);
      if (!v) return std::unexpected(v.error());
      sc_.wheeled.drive_heading_rad = *v * deg;
      drive_heading_set_ = true;
      return {};
    }};
    numbers("distance_m", {&sc_.wheeled.distance_m}, 0, 1000, V);
    numbers("drive_turn_deg", {&sc_.wheeled.drive_turn_rad}, -360, 360, V, deg);
    numbers("drive_s", {&sc_.wheeled.drive_start_s, &sc_.wheeled.drive_duration_s}, 0, 1e6, V);
    rules_["turn"] = {3, 3, false, V, [this](const Args& a) -> Status {
      auto t = num(a[0], 0, 1e6);
      if (!t) return std::unexpected(t.error());
      auto ang = num(a[1], -360, 360);
      if (!ang) return std::unexpected(ang.error());
      auto peak = num(a[2], 0.1, 5000);
      if (!peak) return std::unexpected(peak.error());
      sc_.wheeled.turn = {*t, *ang * deg, *peak * deg};
      return {};
    }};
  }

  // Hand-held.
  void define_handheld_rules() {
    const auto H = MotionKind::handheld;
    numbers("sway_m", {&sc_.handheld.sway_m}, 0, 1, H);
    numbers("sway_deg", {&sc_.handheld.sway_deg}, 0, 45, H);
    numbers("sway_hz", {&sc_.handheld.sway_hz}, 0, 20, H);
    rules_["shake"] = {6, 6, true, H, [this](const Args& a) -> Status {
      double v[6];
      const double lo[6] = {0, 0.01, 0, -1, -1, -1}, hi[6] = {1e6, 10, 5000, 1, 1, 1};
      for (int j = 0; j < 6; ++j) {
        auto x = num(a[j], lo[j], hi[j]);
        if (!x) return std::unexpected(x.error());
        v[j] = *x;
      }
      const Eigen::Vector3d axis(v[3], v[4], v[5]);
      if (axis.norm() < 1e-6) return std::unexpected(where() + "'shake': the axis must not be zero");
      sc_.handheld.shakes.push_back({v[0], v[1], axis.normalized(), v[2] * deg});
      return {};
    }};
  }

  // IMU (on the camera).
  void define_imu_rules() {
    ImuParams& m = sc_.imu;
    numbers("imu_rate_hz", {&m.rate_hz}, 1, 100000);
    numbers("gyro_noise_radps_rthz", {&m.gyro_noise_radps_rthz}, 0, 1);
    numbers("accel_noise_mps2_rthz", {&m.accel_noise_mps2_rthz}, 0, 10);
    numbers("gyro_bias_radps", {&m.gyro_bias_radps}, 0, 1);
    numbers("accel_bias_mps2", {&m.accel_bias_mps2}, 0, 10);
    numbers("gyro_bias_walk_radps_rths", {&m.gyro_bias_walk_radps_rths}, 0, 1);
    numbers("accel_bias_walk_mps2_rths", {&m.accel_bias_walk_mps2_rths}, 0, 10);
    numbers("gyro_scale_error", {&m.gyro_scale_error}, 0, 0.5);
    numbers("accel_scale_error", {&m.accel_scale_error}, 0, 0.5);
    numbers("gyro_range_degps", {&m.gyro_range_radps}, 1, inf, std::nullopt, deg);
    numbers("accel_range_mps2", {&m.accel_range_mps2}, 1, inf);
    numbers("imu_dropouts", {&m.dropouts_per_s, &m.dropout_s}, 0, 100);
    numbers("imu_clock_offset_s", {&m.clock_offset_s}, -1e6, 1e6);
    numbers("imu_clock_drift_ppm", {&m.clock_drift}, -1e5, 1e5, std::nullopt, 1e-6);
  }

  // Closed loop: bus timing, head dynamics, camera delivery, faults.
  void define_closed_loop_rules() {
    numbers("bus_latency_us", {&sc_.bus.latency_us}, 0, 1e6);
    numbers("bus_jitter_us", {&sc_.bus.jitter_us}, 0, 1e6);
    numbers("bus_drop_rate", {&sc_.bus.drop_rate}, 0, 1);
    numbers("command_latency_us", {&sc_.bus.command_latency_us}, 0, 1e6);
    HeadDynamics& h = sc_.head_dynamics;
    numbers("head_time_constant_s", {&h.time_constant_s}, 1e-4, 10);
    numbers("head_rate_limit_radps", {&h.rate_limit_radps}, 0.01, 100);
    numbers("head_accel_limit_radps2", {&h.accel_limit_radps2}, 0.1, 1e5);
    numbers("head_backlash_rad", {&h.backlash_rad}, 0, 0.5);
    numbers("head_friction_radps2", {&h.friction_radps2}, 0, 1e4);
    numbers("head_state_rate_hz", {&h.state_rate_hz}, 1, 10000);
    numbers("head_servo_rate_hz", {&h.servo_rate_hz}, 100, 100000);
    numbers("head_command_timeout_s", {&h.command_timeout_s}, 0.001, 1e6);
    numbers("camera_latency_s", {&sc_.camera_latency_s}, 0, 10);
    rules_["fault"] = {3, 4, true, std::nullopt, [this](const Args& a) -> Status {
      FaultWindow f;
      std::size_t next = 1;
      if (a[0] == "imu_dropout") f.kind = FaultKind::imu_dropout;
      else if (a[0] == "bus_off") f.kind = FaultKind::bus_off;
      else if (a[0] == "camera_stall") f.kind = FaultKind::camera_stall;
      else if (a[0] == "stuck_joint") {
        f.kind = FaultKind::stuck_joint;
        if (a[1] == "pan") f.joint = Joint::pan;
        else if (a[1] == "tilt") f.joint = Joint::tilt;
        else return std::unexpected(where() + "'fault stuck_joint': unknown joint '" + a[1] + "' (known: pan, tilt)");
        next = 2;
      } else {
        return std::unexpected(where() + "'fault': unknown fault '" + a[0] +
                               "' (known: imu_dropout, bus_off, camera_stall, stuck_joint)");
      }
      if (a.size() != next + 2)
        return std::unexpected(where() + "'fault " + a[0] + "' takes " + (next == 2 ? "JOINT " : "") +
                               "START_S DURATION_S");
      auto t = num(a[next], 0, 1e6);
      if (!t) return std::unexpected(t.error());
      auto d = num(a[next + 1], 0, 1e6);
      if (!d) return std::unexpected(d.error());
      f.start_s = *t;
      f.duration_s = *d;
      sc_.faults.push_back(f);
      return {};
    }};
  }

  std::string name_, base_dir_, key_;
  int line_ = 0, burst_line_ = 0;
  bool motion_seen_ = false, drive_heading_set_ = false;
  Scenario sc_;
  std::map<std::string, Rule> rules_;
};

}  // namespace

std::expected<Scenario, std::string> parse_scenario(const std::string& text, const std::string& name) {
  return Parser(name).parse(text);
}

}  // namespace epichead::sim
