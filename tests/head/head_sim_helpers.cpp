#include "head_sim_helpers.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace epichead::head::testing {
namespace {

constexpr double pi = std::numbers::pi;
// max over tau of sin^3(pi tau) cos(pi tau), at tan^2 = 3.
const double kShapePeak = std::pow(std::sqrt(3.0) / 2.0, 3) * 0.5;

double quantise(double v, double lsb) { return std::nearbyint(v / lsb) * lsb; }

}  // namespace

void require_within_position_and_rate_limits(const firmware_iface::HeadCommand& command, const HeadControllerOptions& o) {
  REQUIRE(command.pan_rad >= o.pan.min_rad);
  REQUIRE(command.pan_rad <= o.pan.max_rad);
  REQUIRE(command.tilt_rad >= o.tilt.min_rad);
  REQUIRE(command.tilt_rad <= o.tilt.max_rad);
  REQUIRE(std::abs(command.pan_rate_radps) <= o.pan.rate_max_radps + 1e-12);
  REQUIRE(std::abs(command.tilt_rate_radps) <= o.tilt.rate_max_radps + 1e-12);
}

std::vector<BodyBurst> walking_bursts(double duration_s, std::uint64_t seed, double jerk) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<BodyBurst> out;
  for (double t0 = 0.3; t0 < duration_s; t0 += 1.4) {
    const double phi = 2 * pi * u01(rng);
    const double yaw = -0.3 + 0.6 * u01(rng);
    BodyBurst b;
    b.t0_s = t0;
    b.axis_body = Eigen::Vector3d(std::cos(phi), std::sin(phi), yaw).normalized();
    b.peak_rate_radps = (30 + 50 * u01(rng)) * jerk * pi / 180;
    out.push_back(b);
  }
  return out;
}

Eigen::Vector3d body_rate_radps(const std::vector<BodyBurst>& bursts, double t_s) {
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (const BodyBurst& b : bursts) {
    const double tau = (t_s - b.t0_s) / b.duration_s;
    if (tau <= 0 || tau >= 1) continue;
    const double s = std::sin(pi * tau), c = std::cos(pi * tau);
    w += b.axis_body * (b.peak_rate_radps * s * s * s * c / kShapePeak);
  }
  return w;
}

HeadPlant::HeadPlant(const HeadMount& mount, const PlantOptions& options, std::vector<BodyBurst> bursts, JointAngles start)
    : mount_(mount), options_(options), bursts_(std::move(bursts)), q_(start), q_out_(start), rng_(options.seed) {}

void HeadPlant::send(double t_s, const firmware_iface::HeadCommand& command) {
  pending_.push_back({t_s + options_.command_latency_s, command});
}

Eigen::Quaterniond HeadPlant::world_R_cam() const {
  return world_R_body_ * Eigen::Quaterniond(body_T_cam(mount_, q_out_).linear());
}

void HeadPlant::advance_to(double t_s) {
  constexpr double h = 1e-4;
  while (t_s_ + 0.5 * h < t_s) {
    while (!pending_.empty() && pending_.front().apply_t_s <= t_s_ + 1e-12) {
      active_ = pending_.front().command;
      pending_.pop_front();
    }
    const Eigen::Vector3d w_body = body_rate_radps(bursts_, t_s_ + 0.5 * h);
    Eigen::Vector2d ref = Eigen::Vector2d::Zero();
    if (active_) {
      ref.x() = active_->pan_rate_radps + options_.position_gain_per_s * (active_->pan_rad - q_.pan_rad);
      ref.y() = active_->tilt_rate_radps + options_.position_gain_per_s * (active_->tilt_rad - q_.tilt_rad);
    }
    qd_ += (ref - qd_) * (h / options_.motor_lag_s);
    qd_ = qd_.cwiseMax(-options_.motor_rate_max_radps).cwiseMin(options_.motor_rate_max_radps);
    if (stuck_pan_) qd_.x() = 0;
    q_.pan_rad += qd_.x() * h;
    q_.tilt_rad += qd_.y() * h;
    if (options_.backlash_rad > 0) {
      // The output rests inside the dead band and is pushed at either edge.
      const double half = 0.5 * options_.backlash_rad;
      const JointAngles before = q_out_;
      q_out_.pan_rad = std::clamp(q_out_.pan_rad, q_.pan_rad - half, q_.pan_rad + half);
      q_out_.tilt_rad = std::clamp(q_out_.tilt_rad, q_.tilt_rad - half, q_.tilt_rad + half);
      qd_out_ = Eigen::Vector2d(q_out_.pan_rad - before.pan_rad, q_out_.tilt_rad - before.tilt_rad) / h;
    } else {
      q_out_ = q_;
      qd_out_ = qd_;
    }
    const Eigen::Matrix<double, 3, 2> J = joint_axes_cam(mount_, q_out_);
    const Eigen::Matrix3d cam_R_body = body_T_cam(mount_, q_out_).linear().transpose();
    camera_rate_ = cam_R_body * w_body + J * qd_out_;
    const Eigen::Vector3d phi = w_body * h;
    world_R_body_ = (world_R_body_ * Eigen::Quaterniond(Eigen::AngleAxisd(phi.norm(), phi.norm() > 0 ? phi.normalized() : Eigen::Vector3d::UnitX()))).normalized();
    t_s_ += h;
  }
}

GyroReading HeadPlant::gyro(double t_s) {
  std::normal_distribution<double> n(0.0, options_.gyro_noise_radps);
  Eigen::Vector3d noise = Eigen::Vector3d::Zero();
  if (options_.gyro_noise_radps > 0) noise = Eigen::Vector3d(n(rng_), n(rng_), n(rng_));
  return {t_s, camera_rate_ + options_.gyro_bias_radps + noise};
}

JointState HeadPlant::head_state(double t_s) const {
  JointState s;
  s.t_s = t_s;
  s.angles = {quantise(q_.pan_rad, 1e-4), quantise(q_.tilt_rad, 1e-4)};
  s.pan_rate_radps = quantise(qd_.x(), 0.005);
  s.tilt_rate_radps = quantise(qd_.y(), 0.005);
  return s;
}

ClosedLoop::ClosedLoop(HeadController controller, HeadPlant plant, LoopOptions options)
    : controller_(std::move(controller)), plant_(std::move(plant)), options_(options) {
  outputs_.reserve(20000);
}

Eigen::Vector3d ClosedLoop::target_cam() const {
  // The head sits at the body origin's mount; the body does not translate in these tests.
  const Eigen::Isometry3d world_T_body(plant_.world_R_body());
  const Eigen::Isometry3d world_T_cam = head::world_T_cam(world_T_body, controller_.options().mount, plant_.angles());
  const double sway = std::sin(2 * M_PI * t_s_ / options_.target_sway_period_s);
  return world_T_cam.inverse() * (options_.target_world + options_.target_velocity_mps * t_s_ + options_.target_sway_m * sway);
}

double ClosedLoop::target_angle_rad() const {
  const Eigen::Vector3d p = target_cam().normalized();
  return std::atan2(p.head<2>().norm(), p.z());
}

const ControlOutput& ClosedLoop::tick() {
  t_s_ += 1e-3;
  plant_.advance_to(t_s_);
  ControlInput in;
  in.t_s = t_s_;
  if (imu_on) in.gyro = plant_.gyro(t_s_);
  if (head_state_on) in.head = plant_.head_state(t_s_);
  in.bus = bus_off ? hw::CanBusState::BusOff : hw::CanBusState::ErrorActive;
  if (tracker_on && t_s_ >= next_exposure_s_) {
    Eigen::Vector3d p = target_cam();
    if (options_.target_noise_rad > 0) {
      std::normal_distribution<double> n(0.0, options_.target_noise_rad);
      p = Eigen::AngleAxisd(n(rng_), Eigen::Vector3d::UnitX()) * (Eigen::AngleAxisd(n(rng_), Eigen::Vector3d::UnitY()) * p);
    }
    in_processing_.push_back({t_s_, p});
    next_exposure_s_ = t_s_ + options_.frame_period_s;
  }
  if (!in_processing_.empty() && t_s_ >= in_processing_.front().exposure_s + options_.processing_s - 1e-9) {
    in.target = TargetObservation{options_.stamp_at_arrival ? t_s_ : in_processing_.front().exposure_s,
                                  in_processing_.front().target_cam};
    in_processing_.pop_front();
  }
  outputs_.push_back(controller_.step(in));
  const ControlOutput& out = outputs_.back();
  for (int i = 0; i < out.event_count; ++i) events_.push_back(out.events[static_cast<std::size_t>(i)]);
  if (out.dispatch == Dispatch::Send && !bus_off) plant_.send(t_s_, out.command);
  return out;
}

RateRms camera_rate_rms(const HeadControllerOptions& o, const PlantOptions& plant, double seconds, std::uint64_t seed,
                        bool stabilise) {
  auto controller = HeadController::create(o);
  REQUIRE(controller);
  ClosedLoop loop(std::move(*controller), HeadPlant(o.mount, plant, walking_bursts(seconds, seed), {0.0, 0.1}));
  loop.controller().request(ControlMode::Stabilise);
  double sxy = 0, sall = 0;
  const int ticks = static_cast<int>(seconds * 1000);
  for (int i = 0; i < ticks; ++i) {
    if (stabilise) loop.tick();
    else loop.plant().advance_to((i + 1) * 1e-3);
    const Eigen::Vector3d w = loop.plant().true_camera_rate();
    sxy += w.head<2>().squaredNorm();
    sall += w.squaredNorm();
  }
  return {std::sqrt(sxy / ticks), std::sqrt(sall / ticks)};
}

}  // namespace epichead::head::testing
