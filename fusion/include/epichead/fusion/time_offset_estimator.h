#pragma once
// The time offset between the IMU's clock and the camera's, from the data itself: the camera's
// angular rate between two tracked poses must equal the gyro's mean rate over the same
// interval, once the interval is moved onto the IMU clock (t_imu = t_camera + offset). The
// estimate is the offset in [-max, +max] that minimises the summed squared difference over the
// recent pose pairs (a grid search refined by a parabola through the best three points), with
// how much of the camera's rate variation it explains as the confidence. One wrong pose (a
// frame tracked a few degrees off under blur) makes two pairs with rate errors of 100 deg/s,
// which would dominate a plain squared sum: the fit is repeated without the pairs whose
// residual at the first fit is far above the typical one (a median rule, no scene constant). Vectors, not rate
// magnitudes, are compared, so a rotation about one axis cannot be matched by another.
//
// Why not a filter state: the offset is constant per rig and session, shows only while the
// camera turns, and a wrong early value would corrupt the pose filter; a batch fit over a few
// seconds of motion is robust and cheap, and the caller decides when to adopt it.
// Fixed storage from create(); add_gyro and add_pose do not allocate.
#include <cstddef>
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace epichead::fusion {

struct TimeOffsetOptions {
  double max_offset_s = 0.1;        // search range: +-this
  double step_s = 0.0005;           // grid step before the parabolic refinement
  double window_s = 4.0;            // pose pairs from this far back are used
  double imu_rate_hz = 1000;        // sizes the gyro store
  double max_pair_gap_s = 0.1;      // consecutive poses further apart than this break the chain
  // A pose is paired with the newest earlier pose at least this long before it (3 frames at
  // 30 Hz), along an unbroken chain. Between consecutive frames the turn is small against the
  // poses' own jitter, and the fit explained little: over 0.1 s the turn is several times larger
  // and the jitter the same (docs/fusion.md, "Pairs 0.1 s apart"). 0: the previous pose.
  double pair_span_s = 0.09;
  int min_pairs = 45;             // 1.5 s of poses at 30 Hz
  double min_rate_rms_radps = 0.15;  // the camera must turn at least this much (RMS) to tell
  double min_explained = 0.6;       // fraction of the rate variation the fit must explain
  // A pair is an outlier when its residual at the first fit exceeds this many times the median
  // residual (3: about 4.4 sigma for a Rayleigh-like residual norm, so noise alone rarely trips it).
  double outlier_factor = 3.0;
  Eigen::Matrix3d cam_R_imu = Eigen::Matrix3d::Identity();
};

struct TimeOffsetEstimate {
  double offset_s = 0;              // t_imu = t_camera + offset_s
  double explained = 0;             // 1 - residual / variation of the camera's rate
  int pairs = 0;                    // pairs used in the final fit
  int outlier_pairs = 0;            // pairs left out as outliers
  double rate_rms_radps = 0;        // the camera's rate RMS over the pairs (excitation)
  bool at_search_edge = false;      // the best grid point was at +-max_offset_s
};

class TimeOffsetEstimator {
 public:
  static std::expected<TimeOffsetEstimator, std::string> create(const TimeOffsetOptions& options = {});

  // A gyro sample on the IMU clock, IMU axes. Out-of-order or non-finite samples are ignored.
  void add_gyro(double t_imu_s, const Eigen::Vector3d& gyro_radps);
  // A good tracked pose on the camera clock. Non-finite or out-of-order poses are ignored.
  void add_pose(double t_cam_s, const Eigen::Isometry3d& cam_T_obj);

  // The fit over the recent pairs whatever its quality (empty without enough pairs or gyro).
  std::optional<TimeOffsetEstimate> fit() const;
  // The fit when it passes the options' quality bars (pairs, excitation, explained, not at the
  // edge of the search range).
  std::optional<TimeOffsetEstimate> estimate() const;
  // The bars a fit misses, each with its value and the bar ("the camera turned 0.05 rad/s RMS,
  // 0.15 needed"), joined by "; "; empty when it passes them.
  std::string shortfall(const TimeOffsetEstimate& fit) const;

 private:
  explicit TimeOffsetEstimator(const TimeOffsetOptions& options);
  // Mean gyro (camera axes) over [a, b] on the IMU clock; false when outside the stored span.
  bool mean_rate(double a, double b, Eigen::Vector3d& out) const;
  struct Pair {
    double t0_s, t1_s;        // camera clock
    Eigen::Vector3d rate;     // camera axes, rad/s
  };
  bool usable(const Pair& p) const;
  double cost(double offset_s) const;  // over the pairs marked in use_
  // Grid search and parabola over the pairs in use_: the best offset and its cost.
  double best_offset(double& best_cost, bool& at_edge) const;
  TimeOffsetOptions options_;
  // Gyro samples and the running integral of the rate (camera axes) at each, oldest first.
  std::vector<double> t_;
  std::vector<Eigen::Vector3d> integral_;
  std::vector<Pair> pairs_;  // oldest first
  mutable std::vector<double> costs_;  // fit()'s grid, sized at create()
  mutable std::vector<unsigned char> use_;  // fit()'s per-pair flag (usable, not an outlier)
  mutable std::vector<double> residuals_;   // fit()'s scratch for the median, sized at create()
  // The recent poses of the current chain (camera clock, cam_R_obj), oldest first: the pairs'
  // earlier ends.
  struct Recent {
    double t_s;
    Eigen::Matrix3d R;
  };
  std::vector<Recent> recent_;
  Eigen::Vector3d last_gyro_ = Eigen::Vector3d::Zero();
};

}  // namespace epichead::fusion
