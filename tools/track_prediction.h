#pragma once
// Where `epichead track` places each frame's windows: the pose predicted at the frame's time,
// from the IMU (--imu on) or from a constant-velocity model of the tracked poses (--imu off).
// After a loss the prediction restarts from the last good pose (with the IMU, after a long loss,
// turned as the gyro turned the camera).
#include <expected>
#include <memory>
#include <optional>
#include <string>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "epichead/fusion/carried_orientation.h"
#include "epichead/fusion/predictor.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/offline/sequence.h"

namespace epichead::tools {

// The world's up in the camera frame and the object's up in its own (unit vectors), and how far a
// pose may tilt from them before it counts as a wrong lock.
struct Upright {
  Eigen::Vector3d up_cam, up_obj;
  double max_tilt_rad = 0;
};

class TrackPredictor {
 public:
  virtual ~TrackPredictor() = default;
  // Predicted cam_T_obj at camera time t_s (after the first observe()).
  virtual Eigen::Isometry3d predict(double t_s) = 0;
  // The tracker's result for the frame exposed at t_s.
  virtual void observe(double t_s, const vision::FrameReport& report) = 0;
  // After observe(t_s): the fused estimate at t_s (the filter's posterior: the vision pose
  // weighed against the IMU's propagation, or the propagation alone when the pose was gated
  // out), or nothing when the predictor only extrapolates the vision poses.
  virtual std::optional<Eigen::Isometry3d> fused(double t_s) = 0;
  // For a frame the tracker lost at t_s (after observe(t_s)): the filter's propagation when it
  // applied a vision pose no longer than max_age_s before, or nothing (no IMU, or too long ago:
  // the propagation is then the IMU's alone, drifting).
  virtual std::optional<Eigen::Isometry3d> coasted(double t_s, double max_age_s) {
    (void)t_s;
    (void)max_age_s;
    return std::nullopt;
  }
  // A second opinion for a frame the tracker loses from predict(t_s): the vision poses
  // extrapolated alone, when the predictor is more than that (the IMU); nothing otherwise.
  virtual std::optional<Eigen::Isometry3d> fallback(double t_s) { (void)t_s; return std::nullopt; }
  // With the IMU: true when a tracked pose exposed at t_s tilts the object away from the down the
  // accelerometer measures (fusion::Predictor::check_tilt): a wrong lock, to be taken as lost.
  // `error_rad` is tilt_error_rad(t_s, the pose), measured once by the caller.
  virtual bool against_gravity(double t_s, std::optional<double> error_rad) {
    (void)t_s;
    (void)error_rad;
    return false;
  }
  // With the IMU and the object's down learnt: how far that pose tilts the object from the down
  // the accelerometer measures (rad), for report.json; nothing otherwise.
  virtual std::optional<double> tilt_error_rad(double t_s, const Eigen::Isometry3d& cam_T_obj) {
    (void)t_s;
    (void)cam_T_obj;
    return std::nullopt;
  }
  // A recheck replaced the tracked pose, in doubt since lock_since_s, by `cam_T_obj` at t_s (before
  // restart()): with the IMU, a down learnt since then that the pose contradicts was the lock's
  // and is forgotten (fusion::Predictor::replace_wrong_lock).
  virtual void replace_wrong_lock(double t_s, const Eigen::Isometry3d& cam_T_obj, double lock_since_s) {
    (void)t_s;
    (void)cam_T_obj;
    (void)lock_since_s;
  }
  // With the IMU and the object's down learnt: which way is up at t_s, for detection.
  virtual std::optional<Upright> upright(double t_s) const {
    (void)t_s;
    return std::nullopt;
  }
  // With the IMU: the object's orientation the gyro carried from when the filter last knew it
  // (fusion/carried_orientation.h), kept across the filter's reset after a long loss, for
  // detection to look for; nothing otherwise, or before the filter knew it.
  virtual std::optional<fusion::OrientationPrior> carried_orientation(double t_s) const {
    (void)t_s;
    return std::nullopt;
  }
  // With the IMU: true when `cam_T_obj`, tracked at t_s, is turned from carried_orientation(t_s)
  // by more than fusion::carried_turn_tolerance_deg (as far as the model's symmetries and a body of
  // revolution's free turn let an outline tell); false without one.
  virtual bool turned_from_carried(double t_s, const Eigen::Isometry3d& cam_T_obj) const {
    (void)t_s;
    (void)cam_T_obj;
    return false;
  }
  // ... and the filter has forgotten its state after a long loss, so nothing else judges the pose:
  // a re-lock from the prediction onto clutter, to be taken as lost. Counted.
  virtual bool against_carried_turn(double t_s, const Eigen::Isometry3d& cam_T_obj) {
    (void)t_s;
    (void)cam_T_obj;
    return false;
  }
  // Detection found the object again at t_s (after a loss): predictions restart from this pose
  // at rest, as from init.csv.
  virtual void restart(double t_s, const Eigen::Isometry3d& cam_T_obj) = 0;
  // After observe(t_s): the filter's verdict on that frame's pose against the filter as it was
  // (before any restart the pose caused), or nothing when there is no filter or it was not given
  // the pose. A recheck's switch is on probation on it (tools/switch_probation.h).
  virtual std::optional<fusion::VisionVerdict> verdict() const { return std::nullopt; }
  // A copy in its present state: the filter from before a recheck's switch, kept while the switch
  // is on probation.
  virtual std::unique_ptr<TrackPredictor> clone() const = 0;
  // After observe(t_s): what the filter did with that frame's pose, for report.json's per_frame
  // ({"verdict", "nis", "restart", "strongly_supported"}); null when there is no filter or it was
  // not given the pose.
  virtual nlohmann::json frame_verdict() const { return nullptr; }
  // Counters for report.json.
  virtual nlohmann::json diagnostics() const = 0;
};

// The camera-IMU clock offset as the user gave it (--imu-time-offset-s, --imu-time-offset-sigma-s).
struct ImuClock {
  // How far the IMU's clock runs ahead of the camera's (t_camera = t_imu - offset). Without a
  // value (auto) it starts at 0 and is estimated from the tracked poses and the gyro
  // (fusion/time_offset_estimator.h); once the estimate is confident the filter restarts with it.
  std::optional<double> offset_s;
  // Its 1-sigma, which each vision pose's covariance carries as the pose's motion over that time.
  // Without a value: 0 for a given offset, 10 ms while an auto one is not yet estimated.
  std::optional<double> sigma_s;
};

// --imu on needs the sequence's imu.csv; the error says so when it is missing.
// object_up_obj (--object-up, unit): the object's up in its model frame when the user knows it;
// the gravity check then takes its down from the first frame instead of learning it.
std::expected<std::unique_ptr<TrackPredictor>, std::string> make_track_predictor(const vision::Sequence& seq, bool use_imu,
                                                                                 const ImuClock& clock,
                                                                                 const std::optional<Eigen::Vector3d>& object_up_obj);

}  // namespace epichead::tools
