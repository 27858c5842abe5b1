#include "track_prediction.h"

namespace epichead::tools {
namespace {

// Constant velocity in SE(3): the last relative motion between good poses, scaled to the
// elapsed time and applied on the left (where camera motion acts on cam_T_obj).
class ConstantVelocityPredictor final : public TrackPredictor {
 public:
  // Starts from the given pose (init.csv) at rest.
  ConstantVelocityPredictor(double t_s, const Eigen::Isometry3d& cam_T_obj) : last_(cam_T_obj), last_t_s_(t_s) {}
  Eigen::Isometry3d predict(double t_s) override {
    if (!have_motion_ || !(last_t_s_ > prev_t_s_)) return last_;
    const double s = (t_s - last_t_s_) / (last_t_s_ - prev_t_s_);
    const Eigen::Isometry3d delta = last_ * prev_.inverse();
    const Eigen::AngleAxisd rot(delta.rotation());
    Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
    step.linear() = Eigen::AngleAxisd(s * rot.angle(), rot.axis()).toRotationMatrix();
    step.translation() = s * delta.translation();
    return step * last_;
  }
  void observe(double t_s, const vision::FrameReport& report) override {
    if (report.status == vision::TrackStatus::Lost) {
      ++lost_;
      have_motion_ = false;  // keep trying from the last good pose, without extrapolating
      return;
    }
    prev_ = last_;
    prev_t_s_ = last_t_s_;
    have_motion_ = true;
    last_ = report.cam_T_obj;
    last_t_s_ = t_s;
  }
  nlohmann::json diagnostics() const override { return {{"model", "constant_velocity"}, {"lost_frames", lost_}}; }

 private:
  Eigen::Isometry3d last_, prev_ = Eigen::Isometry3d::Identity();
  double last_t_s_ = 0, prev_t_s_ = 0;
  bool have_motion_ = false;
  int lost_ = 0;
};

}  // namespace

std::expected<std::unique_ptr<TrackPredictor>, std::string> make_track_predictor(const vision::Sequence& seq, bool use_imu) {
  if (use_imu) {
    if (!seq.has_imu()) return std::unexpected("--imu on: " + seq.dir() + " has no imu.csv");
    return std::unexpected("--imu on: the IMU predictor is not wired yet");
  }
  return std::make_unique<ConstantVelocityPredictor>(seq.init().t_s, seq.init().cam_T_obj);
}

}  // namespace epichead::tools
