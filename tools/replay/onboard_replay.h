#pragma once
// Re-runs the onboard estimators over a log's streams as they would have seen them live:
//
// - the fusion predictor over the IMU samples (device clock). A log has no camera poses, so the
//   predictor starts from a reference pose (the camera at the origin of an arbitrary, fixed
//   frame) once gravity has been averaged, and is re-started from its own prediction every
//   second so that it never runs long on the IMU alone. It reports how the IMU stream would
//   feed it (samples accepted and rejected by reason, dropouts and their length), how fast the
//   prediction's 1-sigma uncertainty grows over one camera frame and over one second without
//   vision (what window placement has to cover), and the camera's attitude over time.
// - the head controller (in Stabilise) on a 1 kHz grid of log time over the gyro and head-state
//   streams: which watchdog faults it would raise (IMU stale, head state stale) and when, and
//   how many inputs it would reject.
#include <cstdint>
#include <expected>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "epichead/firmware_iface/head_state.h"
#include "epichead/fusion/predictor.h"
#include "epichead/head/head_controller.h"
#include "replay/bounded_series.h"
#include "replay/log_analysis.h"

namespace epichead::tools::replay {

struct OnboardReplayOptions {
  fusion::PredictorOptions predictor;
  head::HeadControllerOptions controller;
  double frame_period_s = 1.0 / 30;  // the prediction's growth is reported over this
  double restart_period_s = 1.0;     // the predictor re-starts from its own prediction this often
  double control_rate_hz = 1000;
};

class OnboardReplay {
 public:
  static std::expected<std::unique_ptr<OnboardReplay>, std::string> create(const OnboardReplayOptions& options = {});

  void add_imu(const ImuObservation& o);
  void add_head_state(double t_s, const firmware_iface::HeadState& s);
  void finish();

  nlohmann::json fusion_json() const;
  nlohmann::json controller_json() const;
  std::string text() const;  // a few lines for the text report
  // Camera attitude (roll about z, pitch about x, yaw about y, deg) relative to the first pose.
  const BoundedSeries<3>& attitude_series() const { return attitude_; }
  double first_t_s() const { return first_t_s_; }

 private:
  explicit OnboardReplay(const OnboardReplayOptions& options, fusion::Predictor predictor, head::HeadController controller);
  void try_start(double t_s);
  void note_growth(double t_s);
  void tick_until(double t_s);

  OnboardReplayOptions options_;
  fusion::Predictor predictor_;
  head::HeadController controller_;

  std::uint64_t imu_fed_ = 0;
  double first_t_s_ = -1;
  // Predictor runs: when the current one started, and the pose to re-start from.
  bool running_ = false;
  double run_start_t_s_ = 0;
  Eigen::Isometry3d reference_ = Eigen::Isometry3d::Identity();
  double started_at_s_ = -1;
  std::uint64_t restarts_ = 0;
  // 1-sigma growth since a start, averaged over the runs that got that far.
  bool frame_noted_ = false, second_noted_ = false;
  double frame_rot_sum_ = 0, frame_pos_sum_ = 0, second_rot_sum_ = 0, second_pos_sum_ = 0;
  int frame_n_ = 0, second_n_ = 0;
  BoundedSeries<3> attitude_;

  // Controller on the log's clock.
  bool have_gyro_ = false, have_head_ = false, ticking_ = false;
  head::GyroReading gyro_;
  head::JointState head_;
  double next_tick_s_ = 0;
  std::uint64_t ticks_ = 0;
  struct Event {
    double t_s;
    std::string what;
  };
  std::vector<Event> first_events_;  // the first few, for the report
  std::uint64_t imu_stale_raised_ = 0, head_stale_raised_ = 0;
  double imu_stale_total_s_ = 0, imu_stale_since_ = -1;
};

}  // namespace epichead::tools::replay
