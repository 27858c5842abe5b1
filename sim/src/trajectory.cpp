#include "epichead/sim/trajectory.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "simulate_random.h"

namespace epichead::sim {
namespace {

constexpr double pi = std::numbers::pi;
// Largest |d/dtau sin^4(pi tau)| (at tau = 1/3): converts a peak rate into a burst amplitude.
constexpr double bump_peak_slope = 0.75 * std::numbers::sqrt3 * pi;

// A scalar function of time with its first two derivatives.
struct Scalar {
  double v = 0, d1 = 0, d2 = 0;
};

// sin^4(pi tau) on tau in [0, 1], zero outside: C3 where it starts and ends.
Scalar bump(double t_s, double t0_s, double duration_s) {
  const double tau = (t_s - t0_s) / duration_s;
  if (tau <= 0 || tau >= 1) return {};
  const double s = std::sin(pi * tau), c = std::cos(pi * tau);
  const double k = 1.0 / duration_s;
  return {s * s * s * s, 4 * pi * s * s * s * c * k, 4 * pi * pi * (3 * s * s * c * c - s * s * s * s) * k * k};
}

// Normalised integral of the bump: 0 before, 1 after, slope (8/3) sin^4 in between.
Scalar smooth_step(double t_s, double t0_s, double duration_s) {
  const double tau = (t_s - t0_s) / duration_s;
  if (tau <= 0) return {};
  if (tau >= 1) return {1, 0, 0};
  const double k = 1.0 / duration_s;
  const double s = std::sin(pi * tau), c = std::cos(pi * tau);
  return {tau - 2.0 / (3 * pi) * std::sin(2 * pi * tau) + 1.0 / (12 * pi) * std::sin(4 * pi * tau),
          8.0 / 3.0 * s * s * s * s * k, 8.0 / 3.0 * 4 * pi * s * s * s * c * k * k};
}

Kinematics translation_motion(const Eigen::Vector3d& p, const Eigen::Vector3d& v, const Eigen::Vector3d& a) {
  Kinematics k;
  k.pose.translation() = p;
  k.vel_mps = v;
  k.accel_mps2 = a;
  return k;
}

Kinematics burst_motion(const Burst& b, double t_s) {
  const Scalar s = bump(t_s, b.t0_s, b.duration_s);
  const double amp = b.peak_rate_radps * b.duration_s / bump_peak_slope;
  return rotation_about(b.axis_body, amp * s.v, amp * s.d1, amp * s.d2);
}

// The walking robot's burst at step k, drawn from its own random stream so any step can be
// evaluated without the others.
Burst walking_burst(const WalkingParams& p, long k) {
  Random rng(p.seed, 11, static_cast<std::uint64_t>(k));
  const double phi = rng.uniform(0, 2 * pi);
  const double yaw_part = rng.uniform(-0.3, 0.3);
  Burst b;
  b.t0_s = p.first_step_s + static_cast<double>(k) * p.step_period_s;
  b.duration_s = p.burst_s;
  b.axis_body = Eigen::Vector3d(std::cos(phi), std::sin(phi), yaw_part).normalized();
  b.peak_rate_radps = rng.uniform(p.burst_min_degps, p.burst_max_degps) * p.jerk * pi / 180.0;
  return b;
}

}  // namespace

Kinematics compose(const Kinematics& a_T_b, const Kinematics& b_T_c) {
  const Eigen::Matrix3d R = a_T_b.pose.linear();
  const Eigen::Vector3d r = R * b_T_c.pose.translation();
  const Eigen::Vector3d w_rel = R * b_T_c.omega_radps;
  const Eigen::Vector3d v_rel = R * b_T_c.vel_mps;
  const Eigen::Vector3d& w = a_T_b.omega_radps;
  const Eigen::Vector3d& al = a_T_b.alpha_radps2;
  Kinematics out;
  out.pose = a_T_b.pose * b_T_c.pose;
  out.omega_radps = w + w_rel;
  out.alpha_radps2 = al + R * b_T_c.alpha_radps2 + w.cross(w_rel);
  out.vel_mps = a_T_b.vel_mps + w.cross(r) + v_rel;
  out.accel_mps2 = a_T_b.accel_mps2 + al.cross(r) + w.cross(w.cross(r)) + 2 * w.cross(v_rel) + R * b_T_c.accel_mps2;
  return out;
}

Kinematics fixed_motion(const Eigen::Isometry3d& a_T_b) {
  Kinematics k;
  k.pose = a_T_b;
  return k;
}

Kinematics rotation_about(const Eigen::Vector3d& axis, double angle_rad, double rate_radps, double accel_radps2) {
  Kinematics k;
  k.pose.linear() = Eigen::AngleAxisd(angle_rad, axis).toRotationMatrix();
  k.omega_radps = axis * rate_radps;
  k.alpha_radps2 = axis * accel_radps2;
  return k;
}

Trajectory Trajectory::walking(const WalkingParams& p) {
  Trajectory t;
  t.kind_ = Kind::walking;
  t.walk_ = p;
  return t;
}

Trajectory Trajectory::wheeled(const WheeledParams& p) {
  Trajectory t;
  t.kind_ = Kind::wheeled;
  t.wheel_ = p;
  return t;
}

Trajectory Trajectory::handheld(const HandheldParams& p) {
  Trajectory t;
  t.kind_ = Kind::handheld;
  t.hand_ = p;
  t.bursts_ = p.shakes;
  for (Burst& b : t.bursts_) b.peak_rate_radps *= p.jerk;
  std::sort(t.bursts_.begin(), t.bursts_.end(), [](const Burst& a, const Burst& b) { return a.t0_s < b.t0_s; });
  Random rng(p.seed, 12);
  // Incommensurate frequencies and random phases: the sway never repeats within a sequence.
  const double ratios[3] = {1.0, 1.73, 2.91};
  const double weights[3] = {0.65, 0.3, 0.12};
  for (int axis = 0; axis < 6; ++axis) {
    const double amp = axis < 3 ? p.sway_m : p.sway_deg * pi / 180.0;
    for (int i = 0; i < 3; ++i) {
      Sine s;
      s.amp = amp * weights[i];
      s.w_radps = 2 * pi * p.sway_hz * ratios[i] * rng.uniform(0.85, 1.15);
      s.phase_rad = rng.uniform(0, 2 * pi);
      t.sway_[axis].push_back(s);
    }
  }
  return t;
}

Kinematics Trajectory::at(double t_s) const {
  switch (kind_) {
    case Kind::walking: {
      const WalkingParams& p = walk_;
      const Eigen::Vector3d dir(std::cos(p.heading_rad), std::sin(p.heading_rad), 0);
      // Surging advance: speed v (1 - surge cos(w (t - t1))), zero displacement at t = 0.
      const double w = 2 * pi / p.step_period_s, v = p.speed_mps, k = p.surge;
      const double ph = w * (t_s - p.first_step_s), ph0 = -w * p.first_step_s;
      const double x = v * t_s - k * v / w * (std::sin(ph) - std::sin(ph0));
      const double xd = v * (1 - k * std::cos(ph));
      const double xdd = v * k * w * std::sin(ph);
      // Vertical dip at every step; steps near t are the only ones that matter.
      Scalar z;
      const long k_now = static_cast<long>(std::floor((t_s - p.first_step_s) / p.step_period_s));
      const int reach = 1 + static_cast<int>(std::ceil(std::max(p.bob_s, p.burst_s) / p.step_period_s));
      for (long i = k_now - reach; i <= k_now; ++i) {
        if (i < 0) continue;
        const Scalar b = bump(t_s, p.first_step_s + static_cast<double>(i) * p.step_period_s, p.bob_s);
        z.v -= p.bob_m * p.jerk * b.v;
        z.d1 -= p.bob_m * p.jerk * b.d1;
        z.d2 -= p.bob_m * p.jerk * b.d2;
      }
      Kinematics out = translation_motion(p.start_world + dir * x + Eigen::Vector3d(0, 0, z.v),
                                          dir * xd + Eigen::Vector3d(0, 0, z.d1), dir * xdd + Eigen::Vector3d(0, 0, z.d2));
      out = compose(out, rotation_about(Eigen::Vector3d::UnitZ(), p.heading_rad, 0, 0));
      for (long i = k_now - reach; i <= k_now; ++i) {
        if (i < 0) continue;
        const Burst b = walking_burst(p, i);
        if (t_s > b.t0_s && t_s < b.t0_s + b.duration_s) out = compose(out, burst_motion(b, t_s));
      }
      return out;
    }
    case Kind::wheeled: {
      const WheeledParams& p = wheel_;
      const Eigen::Vector3d dir(std::cos(p.drive_heading_rad), std::sin(p.drive_heading_rad), 0);
      const Scalar s = smooth_step(t_s, p.drive_start_s, p.drive_duration_s);
      const double L = p.distance_m;
      Kinematics out = translation_motion(p.start_world + dir * L * s.v, dir * L * s.d1, dir * L * s.d2);
      const Turn& turn = p.turn;
      const double turn_s = 8.0 / 3.0 * std::abs(turn.angle_rad) / std::max(turn.peak_rate_radps, 1e-9);
      Scalar yaw;
      if (turn.angle_rad != 0) yaw = smooth_step(t_s, turn.t0_s, turn_s);
      const double steer = p.drive_turn_rad;
      return compose(out, rotation_about(Eigen::Vector3d::UnitZ(), p.heading_rad + steer * s.v + turn.angle_rad * yaw.v,
                                         steer * s.d1 + turn.angle_rad * yaw.d1, steer * s.d2 + turn.angle_rad * yaw.d2));
    }
    case Kind::handheld: {
      const HandheldParams& p = hand_;
      Scalar q[6];
      for (int axis = 0; axis < 6; ++axis) {
        for (const Sine& s : sway_[axis]) {
          const double a = s.w_radps * t_s + s.phase_rad;
          q[axis].v += s.amp * std::sin(a);
          q[axis].d1 += s.amp * s.w_radps * std::cos(a);
          q[axis].d2 -= s.amp * s.w_radps * s.w_radps * std::sin(a);
        }
      }
      Kinematics out = translation_motion(p.start_world + Eigen::Vector3d(q[0].v, q[1].v, q[2].v),
                                          Eigen::Vector3d(q[0].d1, q[1].d1, q[2].d1),
                                          Eigen::Vector3d(q[0].d2, q[1].d2, q[2].d2));
      out = compose(out, rotation_about(Eigen::Vector3d::UnitZ(), p.heading_rad + q[3].v, q[3].d1, q[3].d2));
      out = compose(out, rotation_about(Eigen::Vector3d::UnitY(), q[4].v, q[4].d1, q[4].d2));
      out = compose(out, rotation_about(Eigen::Vector3d::UnitX(), q[5].v, q[5].d1, q[5].d2));
      for (const Burst& b : bursts_) {
        if (b.t0_s >= t_s) break;
        if (t_s < b.t0_s + b.duration_s) out = compose(out, burst_motion(b, t_s));
      }
      return out;
    }
  }
  return {};
}

double peak_angular_rate_degps(const Trajectory& traj, double t0_s, double t1_s, double dt_s) {
  double peak = 0;
  const long n = static_cast<long>(std::ceil((t1_s - t0_s) / dt_s));
  for (long i = 0; i <= n; ++i) {
    const double t = std::min(t1_s, t0_s + static_cast<double>(i) * dt_s);
    peak = std::max(peak, traj.at(t).omega_radps.norm());
  }
  return peak * 180.0 / pi;
}

}  // namespace epichead::sim
