#pragma once
// The simulated camera behind the hw::CameraPort: frame i is exposed around the scenario's
// frame time (exposure and motion-blur sub-frames of the scene or scenario), rendered from the
// true camera poses along the actual body and joint motion, and becomes readable
// camera_latency_s after its exposure ends. CameraFrame::t_s is the middle of the exposure
// (the program clock is the simulated time); sequence = frame index. A poll that finds several
// frames ready delivers the newest (the older ones count as dropped, as a V4L2 queue overrun
// would); frames whose exposure starts in a camera_stall window never arrive. Frames are
// rendered when delivered (8-bit BGR), or left blank when the world does not render.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "epichead/hw/camera_port.h"
#include "epichead/sim/renderer.h"

namespace epichead::sim {

class SimWorld;

class SimCamera final : public hw::CameraPort {
 public:
  // `renderer` empty: blank frames (timing and truth only). The exposure spans exposure_s,
  // rendered as `subframes` equally weighted instants.
  SimCamera(const SimWorld& world, std::optional<Renderer> renderer, int width_px, int height_px, double exposure_s,
            int subframes);

  std::expected<void, std::string> start() override;
  void stop() override;
  hw::CameraRead next_frame(hw::CameraFrame& out, double timeout_s) override;
  hw::CameraState state() const override { return state_; }
  hw::CameraStats stats() const override { return stats_; }
  std::string_view last_error() const override { return last_error_; }

  // The times of frame i: mid-exposure and when it becomes readable.
  double exposure_mid_s(int frame) const;
  double ready_s(int frame) const;
  int frames_stalled() const { return stalled_; }
  // The last delivered image (BGR), for overlays.
  const cv::Mat& image() const { return image_; }

  // Lets a waiting next_frame() move the world's time (set by the world).
  void set_advance(std::function<void(double)> advance) { advance_ = std::move(advance); }

 private:
  void render(int frame);

  const SimWorld& world_;
  std::optional<Renderer> renderer_;
  int width_px_, height_px_;
  double exposure_s_ = 0;
  int subframes_ = 1;
  hw::CameraState state_ = hw::CameraState::Stopped;
  hw::CameraStats stats_;
  std::string last_error_;
  int next_frame_ = 0;  // first frame not yet delivered or skipped
  int last_delivered_ = -1;
  int stalled_ = 0;
  cv::Mat image_;
  std::vector<SubFrame> subs_;
  std::vector<std::vector<Eigen::Isometry3d>> occluders_;
  std::function<void(double)> advance_;
};

}  // namespace epichead::sim
