#include "epichead/sim/sim_world.h"

#include <cmath>
#include <cstdio>

#include "epichead/firmware_iface/can_ids.h"
#include "epichead/firmware_iface/time_sync.h"
#include "epichead/sim/rig.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/scene_variety.h"
#include "epichead/sim/sim_camera.h"

namespace epichead::sim {
namespace {

namespace fw = firmware_iface;

std::string fmt(const char* format, double a, double b) {
  char buf[160];
  std::snprintf(buf, sizeof buf, format, a, b);
  return buf;
}

// The scenario camera made smaller by an integer factor (pixel centres stay consistent).
vision::Camera downscaled(const vision::Camera& c, int factor) {
  if (factor == 1) return c;
  vision::Intrinsics k = c.intrinsics();
  const double f = factor;
  k.fx_px /= f;
  k.fy_px /= f;
  k.cx_px = (k.cx_px + 0.5) / f - 0.5;
  k.cy_px = (k.cy_px + 0.5) / f - 0.5;
  return vision::Camera(c.width_px() / factor, c.height_px() / factor, k, c.distortion(), c.lens());
}

std::expected<void, std::string> check(const SimWorldOptions& o, const HeadDynamics& h) {
  if (o.camera_downscale != 1 && o.camera_downscale != 2 && o.camera_downscale != 4 && o.camera_downscale != 8)
    return std::unexpected("sim world: camera_downscale must be 1, 2, 4 or 8, not " + std::to_string(o.camera_downscale));
  if (!(o.horizon_s >= 0) || !std::isfinite(o.horizon_s)) return std::unexpected("sim world: horizon_s must be >= 0");
  if (!(o.history_s > 0) || o.history_s > 60) return std::unexpected("sim world: history_s must be in (0, 60]");
  if (!(h.servo_rate_hz >= 100 && h.servo_rate_hz <= 1e6)) return std::unexpected("sim world: servo_rate_hz must be in [100, 1e6]");
  for (double v : {h.time_constant_s, h.rate_limit_radps, h.accel_limit_radps2, h.state_rate_hz, h.status_rate_hz,
                   h.heartbeat_rate_hz, h.command_timeout_s}) {
    if (!(v > 0) || !std::isfinite(v)) return std::unexpected("sim world: head dynamics: rates, limits and times must be positive");
  }
  return {};
}

}  // namespace

class SimWorld::Clock final : public hw::Clock {
 public:
  explicit Clock(const SimWorld& world) : world_(world) {}
  double now_s() const override { return world_.now_s(); }

 private:
  const SimWorld& world_;
};

SimWorld::SimWorld(const Scenario& scenario, const SimWorldOptions& options)
    : scenario_(scenario), options_(options), faults_(scenario.faults) {}

SimWorld::~SimWorld() = default;

std::expected<std::unique_ptr<SimWorld>, std::string> SimWorld::create(const Scenario& given, const SimWorldOptions& options) {
  // A seed's scene variety and the cover boards change the camera path, light and occluder keys
  // as well as the scene: the world runs the scenario as write_sequence does.
  std::optional<ScenarioScene> varied;
  if (given.variety > 0 || !given.covers.empty()) {
    auto made = make_scenario_scene(given);
    if (!made) return std::unexpected(made.error());
    varied = std::move(*made);
  }
  const Scenario& s = varied ? varied->scenario : given;
  if (auto ok = check(options, s.head_dynamics); !ok) return std::unexpected(ok.error());
  auto camera = scenario_camera(s);
  if (!camera) return std::unexpected(camera.error());
  std::unique_ptr<SimWorld> w(new SimWorld(s, options));
  w->camera_model_ = downscaled(*camera, options.camera_downscale);

  // The scene: needed to render, and for its view target when the scenario names no aim.
  std::optional<Scene> scene;
  if (options.camera == CameraOutput::Render || (!s.aim_world && !s.head_deg)) {
    if (varied) {
      scene = std::move(varied->scene);
    } else {
      auto made = make_scene(s.scene);
      if (!made) return std::unexpected(made.error());
      scene = std::move(*made);
    }
    w->world_T_obj_ = scene->world_T_obj;
    w->occlusion_.emplace(*scene, s);
  } else if (varied) {
    w->occlusion_.emplace(varied->scene, s);
  }
  const double exposure_s = s.exposure_s.value_or(scene ? scene->exposure_s : 0.008);
  const int subframes = s.blur_subframes.value_or(scene ? scene->blur_subframes : 1);
  const Rig rig = Rig::from_scenario(s, scene ? scene->view.target_world : Eigen::Vector3d::Zero(), w->world_T_obj_);
  w->body_ = rig.body();
  const HeadAngles head0 = rig.head_angles(0);

  const double last_frame_s = s.frame_time_s(s.frames - 1);
  w->horizon_s_ = options.horizon_s > 0 ? options.horizon_s : last_frame_s + 1.0;
  const double needed_history_s = 1.0 / s.fps + s.camera_latency_s + exposure_s + 0.05;
  if (options.history_s < needed_history_s && options.camera == CameraOutput::Render)
    return std::unexpected(fmt("sim world: history_s %.3f s is shorter than a frame's delivery needs (%.3f s)",
                               options.history_s, needed_history_s));

  w->clock_ = std::make_unique<Clock>(*w);
  SimWorld* self = w.get();
  const auto advance = [self](double t_s) { (void)self->advance_to(std::min(t_s, self->horizon_s_)); };
  w->bus_ = std::make_unique<SimCanBus>(s.bus, w->faults_, s.seed, *w->clock_, advance);
  w->head_ = std::make_unique<SimHeadNode>(s.head_dynamics, head0.pan_rad, head0.tilt_rad);
  w->imu_ = std::make_unique<SimImuNode>(s.imu, s.seed, 0.0, w->horizon_s_);
  std::optional<Renderer> renderer;
  if (options.camera == CameraOutput::Render) {
    RenderOptions ro;
    ro.samples_per_subframe = s.antialias_samples;
    ro.noise_sigma_dn = s.noise_dn;
    renderer.emplace(std::move(*scene), w->camera_model_, ro);
  }
  w->camera_ = std::make_unique<SimCamera>(*w, std::move(renderer), w->camera_model_.width_px(),
                                           w->camera_model_.height_px(), exposure_s, subframes);
  w->camera_->set_advance(advance);
  w->history_ = common::RingBuffer<HeadTick>(static_cast<std::size_t>(std::ceil(options.history_s * s.head_dynamics.servo_rate_hz)) + 2);
  w->run_until(0.0);
  return w;
}

hw::Clock& SimWorld::clock() { return *clock_; }
hw::CanBus& SimWorld::bus() { return *bus_; }
hw::CameraPort& SimWorld::camera() { return *camera_; }
const SimCanBus& SimWorld::sim_bus() const { return *bus_; }
const SimCamera& SimWorld::sim_camera() const { return *camera_; }

std::expected<void, std::string> SimWorld::advance_to(double t_s) {
  if (!(t_s >= now_s_)) return std::unexpected(fmt("sim world: time cannot go back (now %.6f s, asked %.6f s)", now_s_, t_s));
  if (t_s > horizon_s_) return std::unexpected(fmt("sim world: %.6f s is beyond the run's horizon %.6f s", t_s, horizon_s_));
  run_until(t_s);
  now_s_ = t_s;
  return {};
}

Kinematics SimWorld::world_T_cam_motion(double t_s, const HeadAngles& joints) const {
  return compose(body_.at(t_s), body_T_cam(scenario_.mount, joints));
}

void SimWorld::run_until(double t_end_s) {
  const HeadDynamics& h = scenario_.head_dynamics;
  const double tick_s = 1.0 / h.servo_rate_hz;
  enum Source { Tick, Delivery, Imu, State, Status, ImuBeat, HeadBeat };
  for (;;) {
    // The earliest pending event; on a tie the lower source goes first (the servo tick first).
    double t = static_cast<double>(tick_index_) * tick_s;
    Source source = Tick;
    const auto consider = [&](double when, Source s) {
      if (when < t) {
        t = when;
        source = s;
      }
    };
    if (const auto d = bus_->next_delivery_s()) consider(*d, Delivery);
    if (!imu_->done()) consider(imu_->next_true_s(), Imu);
    consider(static_cast<double>(state_index_) / h.state_rate_hz, State);
    consider(static_cast<double>(status_index_) / h.status_rate_hz, Status);
    consider(static_cast<double>(imu_beat_index_) / h.heartbeat_rate_hz, ImuBeat);
    consider((static_cast<double>(head_beat_index_) + 0.5) / h.heartbeat_rate_hz, HeadBeat);
    if (t > t_end_s) return;

    switch (source) {
      case Tick:
        head_->tick(t, faults_.joint_stuck(Joint::pan, t), faults_.joint_stuck(Joint::tilt, t));
        history_.push_overwrite(head_->current());
        ++tick_index_;
        break;
      case Delivery:
        deliver_to_nodes(bus_->pop_delivery(), t);
        break;
      case Imu: {
        const Kinematics motion = world_T_cam_motion(t, output_angles_at(head_->current(), t));
        const ImuNodeSample& s = imu_->measure_next(motion, faults_.active(FaultKind::imu_dropout, t));
        if (s.send) {
          bus_->node_send(s.frames[0], t);
          bus_->node_send(s.frames[1], t);
        }
        break;
      }
      case State:
        bus_->node_send(head_->state_frame(t), t);
        ++state_index_;
        break;
      case Status:
        bus_->node_send(head_->status_frame(), t);
        ++status_index_;
        break;
      case ImuBeat:
        bus_->node_send(imu_->heartbeat_frame(t), t);
        ++imu_beat_index_;
        break;
      case HeadBeat:
        bus_->node_send(head_->heartbeat_frame(t), t);
        ++head_beat_index_;
        break;
    }
  }
}

void SimWorld::deliver_to_nodes(const fw::CanFrame& frame, double t_s) {
  if (frame.id == fw::kIdHeadCommand) {
    head_->deliver(frame, t_s);
    return;
  }
  if (frame.id == fw::kIdTimeSyncRequest && !frame.extended()) {
    const auto request = fw::decode_time_sync_request(frame);
    if (!request) {
      ++stats_.host_frames_ignored;
      return;
    }
    // Each device answers with its own clock at the moment the request reached it.
    fw::TimeSyncReply imu_reply{fw::kNodeImu, request->sequence, imu_->device_us(t_s) & fw::kTimeSyncStampMask};
    const auto head_us = static_cast<std::uint64_t>(std::llround(t_s * 1e6));
    fw::TimeSyncReply head_reply{fw::kNodeHead, request->sequence, head_us & fw::kTimeSyncStampMask};
    for (const auto& reply : {imu_reply, head_reply}) {
      if (auto e = fw::encode(reply)) bus_->node_send(e->frame, t_s);
    }
    ++stats_.time_syncs_answered;
    return;
  }
  ++stats_.host_frames_ignored;
}

bool SimWorld::object_hidden(const SimTruth& truth) {
  return occlusion_ && occlusion_->hides_object(truth.t_s, truth.world_T_cam);
}

std::expected<SimTruth, std::string> SimWorld::truth_at(double t_s) const {
  const double oldest = history_.empty() ? now_s_ : std::max(history_.oldest().t_s, now_s_ - options_.history_s);
  if (!(t_s >= oldest && t_s <= now_s_) || history_.empty())
    return std::unexpected(fmt("sim world: truth is kept from %.6f s to now, %.6f s", oldest, now_s_) + " (asked " +
                           std::to_string(t_s) + " s)");
  // Ticks are evenly spaced: the one that contains t_s, from the front's time.
  const double tick_s = 1.0 / scenario_.head_dynamics.servo_rate_hz;
  auto i = static_cast<std::size_t>(std::max(0.0, std::floor((t_s - history_.oldest().t_s) / tick_s)));
  i = std::min(i, history_.size() - 1);
  // The last tick that started at or before t_s, exactly as the run saw it (an IMU sample an ulp
  // before a tick used the previous one).
  while (i > 0 && history_[i].t_s > t_s) --i;
  while (i + 1 < history_.size() && history_[i + 1].t_s <= t_s) ++i;
  const HeadTick& tick = history_[i];
  SimTruth truth;
  truth.t_s = t_s;
  truth.joints = output_angles_at(tick, t_s);
  const double h = t_s - tick.t_s;
  truth.pan_motor_rad = tick.pan_motor.angle_rad + tick.pan_motor.rate_radps * h + 0.5 * tick.pan_motor.accel_radps2 * h * h;
  truth.tilt_motor_rad =
      tick.tilt_motor.angle_rad + tick.tilt_motor.rate_radps * h + 0.5 * tick.tilt_motor.accel_radps2 * h * h;
  const Kinematics body = body_.at(t_s);
  const Kinematics cam = compose(body, body_T_cam(scenario_.mount, truth.joints));
  truth.world_T_body = body.pose;
  truth.world_T_cam = cam.pose;
  truth.cam_T_obj = cam.pose.inverse() * world_T_obj_;
  true_imu(cam, truth.cam_rate_radps, truth.cam_specific_force_mps2);
  return truth;
}

}  // namespace epichead::sim
