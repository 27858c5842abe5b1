// Scene variety: the object's placement and the camera path (start, heading, aim, speed, motion
// amplitude, timing).
#include "variety_steps.h"

namespace epichead::sim::variety {
namespace {

using Eigen::Vector3d;

Vector3d& start_of(Scenario& s) {
  return s.motion == MotionKind::walking ? s.walking.start_world
         : s.motion == MotionKind::wheeled ? s.wheeled.start_world
                                           : s.handheld.start_world;
}
double& heading_of(Scenario& s) {
  return s.motion == MotionKind::walking ? s.walking.heading_rad
         : s.motion == MotionKind::wheeled ? s.wheeled.heading_rad
                                           : s.handheld.heading_rad;
}

}  // namespace

Eigen::AlignedBox3d model_box(const Scene& s) {
  Eigen::AlignedBox3d box;
  for (const Vector3d& p : s.model.vertices) box.extend(p);
  return box;
}

void place(const Scene& nominal, const Draws& d, double v, Scenario& run, Eigen::Isometry3d& world_T_obj,
           SceneVariety& out) {
  const VarietyLimits& lim = nominal.variety_limits;
  out.object_yaw_deg = v * symmetric(d.yaw) * lim.object_yaw_deg;
  out.object_offset_m = v * lim.object_offset_m * Eigen::Vector2d(symmetric(d.offset_x), symmetric(d.offset_y));
  world_T_obj = Eigen::Isometry3d::Identity();
  world_T_obj.translation() = Vector3d(out.object_offset_m.x(), out.object_offset_m.y(), 0);
  world_T_obj.linear() = Eigen::AngleAxisd(out.object_yaw_deg * deg, Vector3d::UnitZ()).toRotationMatrix();

  // Start: turned about the object, moved nearer or farther within the view's distance range,
  // shifted a little; the heading turns with the orbit so the body still faces the object.
  const Vector3d target = nominal.view.target_world;
  const Eigen::AngleAxisd orbit(v * symmetric(d.orbit) * lim.orbit_deg * deg, Vector3d::UnitZ());
  Vector3d rel = orbit * (start_of(run) - target);
  const bool on_floor = run.motion != MotionKind::handheld;  // a robot's body height stays
  Vector3d scaled = rel;
  const double f = factor(d.distance, 1.2, v);
  if (on_floor) scaled.head<2>() *= f;
  else scaled *= f;
  const double dist = scaled.norm();
  if (dist > nominal.view.max_distance_m || dist < nominal.view.min_distance_m) scaled = rel;  // keep the built-in distance
  rel = scaled;
  Vector3d start = target + rel;
  start.x() += v * symmetric(d.shift_x) * lim.start_shift_m;
  start.y() += v * symmetric(d.shift_y) * lim.start_shift_m;
  if (!on_floor) start.z() += v * symmetric(d.shift_z) * lim.start_shift_m;
  run.walking.start_world = run.wheeled.start_world = run.handheld.start_world = start;
  const double turn = orbit.angle() * (orbit.axis().z() < 0 ? -1 : 1) + v * symmetric(d.heading) * lim.heading_deg * deg;
  const double heading = heading_of(run) + turn;
  run.walking.heading_rad = run.wheeled.heading_rad = run.handheld.heading_rad = heading;
  run.wheeled.drive_heading_rad += turn;  // the drive turns with the body
  out.start_world = start;
  out.heading_deg = heading / deg;

  // Aim: turned with the orbit and moved by up to a quarter of the object's size.
  if (!run.head_deg) {
    const double size = model_box(nominal).sizes().norm();
    out.aim_shift_m = v * 0.25 * size * Vector3d(symmetric(d.aim[0]), symmetric(d.aim[1]), symmetric(d.aim[2])) / 2;
    const Vector3d aim = run.aim_world.value_or(target);
    run.aim_world = target + orbit * (aim - target) + out.aim_shift_m;
  }

  // Speed, motion amplitude and timing.
  out.speed_scale = factor(d.speed, 1.3, v);
  out.motion_scale = factor(d.motion, 1.3, v);
  out.timing_scale = factor(d.timing, 1.15, v);
  out.path_seed = v > 0 ? d.path_seed : run.walking.seed;
  switch (run.motion) {
    case MotionKind::walking: {
      WalkingParams& w = run.walking;
      w.speed_mps *= out.speed_scale;
      w.burst_min_degps *= out.motion_scale;
      w.burst_max_degps *= out.motion_scale;
      w.bob_m *= out.motion_scale;
      w.step_period_s = std::max(w.step_period_s * out.timing_scale, w.burst_s * 1.2);
      w.first_step_s += v * 0.5 * d.first_step;
      w.seed = out.path_seed;
      break;
    }
    case MotionKind::wheeled: {
      WheeledParams& w = run.wheeled;
      // Never farther than built: the drive stays inside the room.
      w.distance_m *= std::min(1.0, out.speed_scale);
      w.drive_start_s = std::max(0.0, w.drive_start_s + v * 0.5 * symmetric(d.drive_t));
      w.turn.t0_s = std::max(0.0, w.turn.t0_s + v * symmetric(d.turn_t));
      w.turn.peak_rate_radps *= out.motion_scale;
      break;
    }
    case MotionKind::handheld: {
      HandheldParams& h = run.handheld;
      h.sway_hz *= out.speed_scale;
      h.sway_m *= out.motion_scale;
      h.sway_deg *= out.motion_scale;
      for (std::size_t i = 0; i < h.shakes.size(); ++i) {
        h.shakes[i].peak_rate_radps *= out.motion_scale;
        h.shakes[i].t0_s = std::max(0.0, h.shakes[i].t0_s + v * 0.4 * symmetric(d.shake_t[i % kMaxShakes]));
      }
      h.seed = out.path_seed;
      break;
    }
  }
}

}  // namespace epichead::sim::variety
