#include "epichead/sim/sim_camera.h"

#include <algorithm>
#include <limits>

#include "epichead/sim/sim_world.h"
#include "occluder_motion.h"
#include "simulate_random.h"

namespace epichead::sim {
namespace {

// The random stream of frame noise: the one write_sequence uses, so a run with the head held
// at the scenario's angles renders the frames `epichead sim` writes.
constexpr std::uint64_t kFrameNoiseStream = 41;

}  // namespace

SimCamera::SimCamera(const SimWorld& world, std::optional<Renderer> renderer, int width_px, int height_px,
                     double exposure_s, int subframes)
    : world_(world),
      renderer_(std::move(renderer)),
      width_px_(width_px),
      height_px_(height_px),
      exposure_s_(exposure_s),
      subframes_(std::max(1, subframes)),
      subs_(static_cast<std::size_t>(subframes_)),
      occluders_(static_cast<std::size_t>(subframes_)) {
  image_ = cv::Mat::zeros(height_px_, width_px_, CV_8UC3);
}

double SimCamera::exposure_mid_s(int frame) const { return world_.scenario().frame_time_s(frame); }

double SimCamera::ready_s(int frame) const {
  return exposure_mid_s(frame) + 0.5 * exposure_s_ + world_.scenario().camera_latency_s;
}

std::expected<void, std::string> SimCamera::start() {
  state_ = hw::CameraState::Streaming;
  last_error_.clear();
  return {};
}

void SimCamera::stop() { state_ = hw::CameraState::Stopped; }

hw::CameraRead SimCamera::next_frame(hw::CameraFrame& out, double timeout_s) {
  if (state_ != hw::CameraState::Streaming) {
    last_error_ = "sim camera: not streaming (call start())";
    return hw::CameraRead::Error;
  }
  const double deadline = timeout_s < 0 ? std::numeric_limits<double>::infinity() : world_.now_s() + timeout_s;
  const int frames = world_.scenario().frames;
  for (;;) {
    const double t = world_.now_s();
    // The newest ready frame that was not lost to a stall; stalled ones are consumed too.
    int pick = -1;
    for (; next_frame_ < frames && ready_s(next_frame_) <= t; ++next_frame_) {
      const double exposure_start = exposure_mid_s(next_frame_) - 0.5 * exposure_s_;
      if (world_.faults().active(FaultKind::camera_stall, exposure_start)) ++stalled_;
      else pick = next_frame_;
    }
    if (pick >= 0) {
      stats_.dropped_frames += static_cast<std::uint64_t>(pick - last_delivered_ - 1);
      last_delivered_ = pick;
      if (renderer_) render(pick);
      out.width = image_.cols;
      out.height = image_.rows;
      out.stride_bytes = static_cast<int>(image_.step[0]);
      out.format = hw::PixelFormat::Bgr24;
      out.fourcc = hw::fourcc_of(hw::PixelFormat::Bgr24);
      out.data = image_.data;
      out.size_bytes = image_.step[0] * static_cast<std::size_t>(image_.rows);
      out.t_s = exposure_mid_s(pick);
      out.sequence = static_cast<std::uint64_t>(pick);
      ++stats_.frames;
      return hw::CameraRead::Frame;
    }
    if (!advance_ || t >= deadline || next_frame_ >= frames) return hw::CameraRead::Timeout;
    // Waiting = letting the world run until the next frame is ready (or the timeout ends).
    advance_(std::min(deadline, ready_s(next_frame_)));
    if (world_.now_s() <= t) return hw::CameraRead::Timeout;  // the world cannot move (its horizon)
  }
}

void SimCamera::render(int frame) {
  const Scenario& s = world_.scenario();
  const double mid = exposure_mid_s(frame);
  for (int k = 0; k < subframes_; ++k) {
    // Sub-frames at the centres of equal slices of the exposure, as write_sequence places them.
    const double tk = mid + exposure_s_ * ((k + 0.5) / subframes_ - 0.5);
    const auto truth = world_.truth_at(std::min(tk, world_.now_s()));
    const auto idx = static_cast<std::size_t>(k);
    occluder_poses_at(renderer_->scene(), s, tk, occluders_[idx]);
    subs_[idx] = {truth ? truth->world_T_cam : Eigen::Isometry3d::Identity(), world_.world_T_obj(), occluders_[idx]};
    if (!truth) ++stats_.corrupt_frames;  // older than the world's history: cannot happen with valid options
  }
  FrameInput input;
  input.t_s = mid;
  input.sub_frames = subs_;
  input.illumination_gain = s.light_gain(mid);
  cv::RNG rng(Random(s.seed, kFrameNoiseStream, static_cast<std::uint64_t>(frame)).next_u64() | 1);
  renderer_->render(input, rng, image_);
}

}  // namespace epichead::sim
