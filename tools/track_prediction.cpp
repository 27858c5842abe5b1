#include "track_prediction.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "epichead/common/chi2_bounds.h"
#include "epichead/fusion/predictor.h"
#include "epichead/fusion/time_offset_estimator.h"
#include "epichead/fusion/vision_arbiter.h"
#include "epichead/vision/constant_velocity.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/pose_estimator.h"
#include "epichead/vision/revolution_axis.h"

namespace epichead::tools {
namespace {

// One frame's report.json per_frame "filter" entry (TrackPredictor::frame_verdict): the same keys
// whichever way the pose went. nis null when the filter did not measure the pose; restart null when
// it did not restart from it.
nlohmann::json filter_verdict_json(const char* verdict, std::optional<double> nis, const char* restart, bool strongly_supported) {
  return {{"verdict", verdict},
          {"nis", nis ? nlohmann::json(*nis) : nlohmann::json(nullptr)},
          {"restart", restart ? nlohmann::json(restart) : nlohmann::json(nullptr)},
          {"strongly_supported", strongly_supported}};
}

// 1-sigma of the camera-IMU time offset while it is unknown (--imu-time-offset-s auto, before the
// estimate is adopted): a recorded imu.csv on its own device clock, as USB or CAN IMUs stamp and
// the simulator writes, is typically some 5-25 ms off the camera's. Measured on the jerk sweep's
// mockup_walk and box_clutter runs (docs/fusion.md): 0 lets a 14 ms offset gate good poses until
// the filter drifts off (mockup_walk at jerk 0.5: 8 % success), 10 ms tracks all four test runs
// best, and 33 ms weighs the poses so little that the filter drifts instead.
constexpr double kUnknownOffsetSigmaS = 0.01;
// After the estimate is adopted: its accuracy (within 1 ms in tests/fusion/test_time_offset_estimator.cpp).
constexpr double kEstimatedOffsetSigmaS = 0.001;

// Without the IMU: the vision poses extrapolated alone (vision/constant_velocity.h).
class ConstantVelocityPredictor final : public TrackPredictor {
 public:
  // Starts from the given pose (init.csv) at rest.
  ConstantVelocityPredictor(double t_s, const Eigen::Isometry3d& cam_T_obj) : motion_(t_s, cam_T_obj) {}
  void restart(double t_s, const Eigen::Isometry3d& cam_T_obj) override { motion_.restart(t_s, cam_T_obj); }
  Eigen::Isometry3d predict(double t_s) override { return motion_.predict(t_s); }
  void observe(double t_s, const vision::FrameReport& report) override {
    lost_ += report.status == vision::TrackStatus::Lost;
    motion_.observe(t_s, report.status, report.cam_T_obj);
  }
  std::optional<Eigen::Isometry3d> fused(double) override { return std::nullopt; }
  std::unique_ptr<TrackPredictor> clone() const override { return std::make_unique<ConstantVelocityPredictor>(*this); }
  nlohmann::json diagnostics() const override { return {{"model", "constant_velocity"}, {"lost_frames", lost_}}; }

 private:
  vision::ConstantVelocity motion_;
  int lost_ = 0;
};

// Consistency of the vision updates: the normalised innovation squared (NIS) of a pose against
// the filter's prediction is chi-square with 6 degrees of freedom when both covariances are
// honest (5 for a body of revolution, whose turn is not compared: fusion/free_direction.h): mean 6
// (5), and 95 % of the values within common::chi2_95_bounds.
class NisStats {
 public:
  void add(double nis, int dims) {
    if (std::isfinite(nis)) values_.push_back({nis, dims});
  }
  nlohmann::json to_json() const {
    if (values_.empty()) return {{"count", 0}};
    std::vector<double> v;
    v.reserve(values_.size());
    double sum = 0, dims = 0;
    int below = 0, above = 0;
    for (const auto& [x, n] : values_) {
      v.push_back(x);
      sum += x;
      dims += n;
      const common::Chi2Bounds b = common::chi2_95_bounds(n);
      below += x < b.low;
      above += x > b.high;
    }
    std::sort(v.begin(), v.end());
    const double n = static_cast<double>(v.size());
    return {{"count", v.size()},
            {"mean", sum / n},
            {"mean_dof", dims / n},
            {"median", v[v.size() / 2]},
            {"below_chi2_2.5pct", below / n},
            {"above_chi2_97.5pct", above / n},
            {"within_95pct_bounds", (n - below - above) / n}};
  }

 private:
  std::vector<std::pair<double, int>> values_;
};

// The Kalman predictor fed with the sequence's imu.csv: before each frame every IMU sample up
// to the frame's time is propagated; each tracked pose is a vision update at its exposure time.
// While the object is lost the gyro keeps the orientation, so windows follow a turning camera;
// after lost_reset_s without a pose the filter restarts from the next one.
class ImuPredictor final : public TrackPredictor {
 public:
  // With an estimator the offset is found from the data (auto) and the filter restarts with it.
  ImuPredictor(const fusion::PredictorOptions& options, fusion::Predictor predictor, const vision::Sequence& seq,
               std::optional<fusion::TimeOffsetEstimator> estimator)
      : options_(options), predictor_(std::move(predictor)), imu_(&seq.imu()), offset_s_(options.imu_time_offset_s),
        fx_px_(seq.camera().intrinsics().fx_px), last_good_(seq.init().cam_T_obj), arbiter_(options.gate_chi2),
        vision_only_(seq.init().t_s, seq.init().cam_T_obj), carried_(options.mount.cam_R_imu, fusion::CarriedOrientationNoise{}),
        last_good_turned_(options.mount.cam_R_imu, fusion::CarriedOrientationNoise{}),
        estimator_(std::move(estimator)) {
    symmetries_ = vision::model_symmetries(seq.model());
    // The initial pose seeds the filter like a vision result with a loose covariance.
    pending_init_ = true;
    init_t_s_ = seq.init().t_s;
    start_pose_ = last_good_;
    note_good(init_t_s_, last_good_);
  }
  Eigen::Isometry3d predict(double t_s) override {
    feed_until(t_s);
    if (pending_init_) {
      const auto r = predictor_.add_vision(init_t_s_, last_good_, vision::initial_pose_covariance());
      pending_init_ = r.verdict != fusion::VisionVerdict::Initialised && r.verdict != fusion::VisionVerdict::Applied;
      seeded_by_init_ = !pending_init_;
      // init.csv's orientation is the user's word; a detection's seed is not (the first pose
      // tracked from it is, once the filter applies it).
      if (seeded_by_init_ && seed_given_) carry(init_t_s_);
    }
    if (auto p = predictor_.predict(t_s)) return p->cam_T_obj;
    ++fallbacks_;
    return last_good_turned(t_s);
  }
  // Without a filter (reset after a long loss, or not yet started): the last good pose turned as
  // the gyro says the camera turned since, about the camera's centre. A head or a wheeled robot
  // turning onto the object moves its camera little beside the turn; the pose as it was would
  // leave the windows where the object was in the image before the turn (held-out late_entry).
  Eigen::Isometry3d last_good_turned(double t_s) const {
    const auto turned = last_good_turned_.at(t_s);
    if (!turned) return last_good_;
    const Eigen::Matrix3d turn = turned->cam_R_obj * last_good_.linear().transpose();
    Eigen::Isometry3d T = last_good_;
    T.linear() = turned->cam_R_obj;
    T.translation() = turn * last_good_.translation();
    return T;
  }
  std::optional<Eigen::Isometry3d> fallback(double t_s) override { return vision_only_.predict(t_s); }
  void restart(double t_s, const Eigen::Isometry3d& cam_T_obj) override {
    // The detected pose seeds the filter as init.csv's does; the next tracked pose at this
    // time then replaces it (observe()).
    predictor_.reset();
    vision_only_.restart(t_s, cam_T_obj);
    note_good(t_s, cam_T_obj);
    init_t_s_ = t_s;
    pending_init_ = true;
    reset_done_ = false;
    arbiter_.clear();
    last_applied_t_s_ = -INFINITY;  // a detected pose is not a tracked one
    seed_given_ = false;
    ++detection_restarts_;
  }
  void observe(double t_s, const vision::FrameReport& report) override {
    vision_only_.observe(t_s, report.status, report.cam_T_obj);
    verdict_ = nullptr;
    first_verdict_.reset();
    if (report.status == vision::TrackStatus::Lost) {
      ++lost_;
      if (t_s - last_good_t_s_ > kLostResetS && !reset_done_) {
        predictor_.reset();
        arbiter_.clear();
        last_applied_t_s_ = -INFINITY;
        reset_done_ = true;
        ++resets_;
      }
      return;
    }
    note_good(t_s, report.cam_T_obj);
    if (!given_tracked_pose() && !reset_done_ && !vision::strongly_supported(report)) {
      // Seeded (init.csv, a detection) but not yet given a pose, the filter is carried by the
      // IMU alone, and with its velocity unknown its position spreads. Once its 1-sigma across
      // the view is wider than a line window, its prediction cannot place the windows: a pose
      // found there is a chance lock, which the filter, that unsure, cannot gate. Such a filter
      // takes only a pose the image supports well, and meanwhile keeps propagating (the gyro
      // keeps its turn). Held-out late_entry 276: init.csv's pose with the object out of view
      // for 0.8 s, then a re-lock 7 deg and 196 mm off (the prediction 245 px 1-sigma) was
      // applied, and the run tracked 0 % (68 % without the IMU).
      const double sigma_px = predicted_sigma_px(t_s);
      if (sigma_px > kUnplaceableSigmaPx) {
        ++weak_poses_unplaceable_;
        verdict_ = filter_verdict_json("held-weak-unplaceable", std::nullopt, nullptr, false);
        verdict_["predicted_sigma_px"] = sigma_px;
        return;
      }
    }
    if (reset_done_ && !vision::strongly_supported(report)) {
      // Found again after a long loss: the filter restarts only from a pose the image fully
      // supports. One re-found from a stale prediction can be a wrong lock, and a filter
      // started on it holds the windows there (can, after its 1 s cover: 14 deg off for good).
      // Meanwhile the windows follow the vision poses (predict() falls back to last_good_).
      ++weak_reacquisitions_;
      verdict_ = filter_verdict_json("held-weak-after-loss", std::nullopt, nullptr, false);
      return;
    }
    reset_done_ = false;
    if (estimator_ && !adopted_) {
      estimator_->add_pose(t_s, report.cam_T_obj);
      // A fit costs about a millisecond: try a few times a second, not every frame. Not on a
      // frame re-locked after a loss or doubtful: the filter restarts from this frame's pose on
      // the new clock, and such a pose may be a wrong lock (fresh held-out stumble 294: re-locked
      // 50 deg off as the estimate became confident; the filter and the orientation carried from
      // it followed the lock). The next frame is tried instead.
      const bool settled = report.status == vision::TrackStatus::Tracked && !vision::has(report.reasons, vision::TrackReason::Reacquired);
      if (++frames_since_fit_ >= kFitEveryFrames && settled) {
        frames_since_fit_ = 0;
        if (const auto e = estimator_->estimate()) {
          const fusion::VisionResult adopted = adopt(*e, t_s, report);
          verdict_ = filter_verdict_json(fusion::to_string(adopted.verdict), std::nullopt, "clock-offset-estimated",
                                         vision::strongly_supported(report));
          return;
        }
      }
    }
    // The first tracked pose at the start pose's own time replaces it as the seed: applied
    // after it, it was refused as out of order, the next frame then moved the filter by the
    // start pose's whole error (a centimetre) in one frame time, and that became a velocity of
    // ~0.3 m/s: the translation ran off 26 mm per frame (office_pan, development seed 3).
    if (seeded_by_init_ && t_s <= init_t_s_) {
      // ... unless it moved away from the start pose by more than the start pose's own
      // uncertainty: then the tracker locked onto something else from it (fresh held-out stumble
      // 287: 66 mm and 7 deg off, on the first frame; seeded from that lock the filter held the
      // windows there for 75 frames, 57.8 % against 89.4 % without the IMU). The start pose keeps
      // the seed and the pose is held; the next frames' poses meet the filter as any other.
      if (!agrees_with_start(report.cam_T_obj)) {
        ++poses_against_start_;
        verdict_ = filter_verdict_json("held-against-start-pose", std::nullopt, nullptr, vision::strongly_supported(report));
        return;
      }
      predictor_.reset();
    }
    seeded_by_init_ = false;
    // Vision and the filter disagree: which is wrong? The arbiter restarts the filter from a
    // pose the image supports well when it was found from the vision-only extrapolation, after
    // three such poses gated in a row, or when gated poses agree (fusion/vision_arbiter.h).
    const fusion::PoseSupport support{vision::strongly_supported(report), report.used_fallback};
    const fusion::ArbitratedVision a = arbiter_.add_vision(predictor_, t_s, report.cam_T_obj, report.covariance, support);
    const fusion::VisionVerdict first = a.result.verdict;
    first_verdict_ = first;
    const bool measured = first == fusion::VisionVerdict::Applied || first == fusion::VisionVerdict::Gated;
    if (measured) nis_.add(a.result.mahalanobis2, a.result.dims);
    const char* restart = fusion::to_string(a.restart);
    verdict_ = filter_verdict_json(fusion::to_string(first), measured ? std::optional(a.result.mahalanobis2) : std::nullopt, restart,
                                   support.strong);
    if (restart) verdict_["after_restart"] = fusion::to_string(a.after_restart.verdict);
    const fusion::VisionResult& r = a.final();
    if (fusion::supersedes_start_pose(r.verdict)) pending_init_ = false;
    if (r.verdict == fusion::VisionVerdict::Initialised || r.verdict == fusion::VisionVerdict::Applied) {
      last_applied_t_s_ = t_s;
      carry(t_s);
    }
  }
  std::optional<fusion::OrientationPrior> carried_orientation(double t_s) const override { return carried_.at(t_s); }
  bool turned_from_carried(double t_s, const Eigen::Isometry3d& cam_T_obj) const override {
    const auto carried = carried_.at(t_s);
    if (!carried) return false;
    const double off_rad = vision::symmetric_turn_rad(cam_T_obj.linear(), carried->cam_R_obj, symmetries_,
                                                      options_.gravity_check.free_turn_axis_obj);
    return off_rad * 180 / std::numbers::pi > fusion::carried_turn_tolerance_deg(*carried);
  }
  bool against_carried_turn(double t_s, const Eigen::Isometry3d& cam_T_obj) override {
    feed_until(t_s);
    if (predictor_.predict(t_s)) return false;  // the filter runs: its gate judges the pose
    if (!turned_from_carried(t_s, cam_T_obj)) return false;
    ++against_carried_turn_;
    return true;
  }
  // Whether the filter has taken a tracked pose since its seed (init.csv, a detection) or its
  // reset after a long loss.
  bool given_tracked_pose() const { return last_applied_t_s_ > -INFINITY; }
  // The prediction's 1-sigma position across the line of sight (the larger of x and y), in
  // pixels at its depth; 0 before the filter starts.
  double predicted_sigma_px(double t_s) {
    const auto p = predictor_.predict(t_s);
    if (!p) return 0;
    const double z = std::max(p->cam_T_obj.translation().z(), 0.05);
    return fx_px_ * std::sqrt(std::max(p->covariance(0, 0), p->covariance(1, 1))) / z;
  }
  std::optional<Eigen::Isometry3d> coasted(double t_s, double max_age_s) override {
    if (!(t_s - last_applied_t_s_ <= max_age_s)) return std::nullopt;
    return fused(t_s);
  }
  std::optional<Eigen::Isometry3d> fused(double t_s) override {
    if (auto p = predictor_.predict(t_s)) return p->cam_T_obj;  // nothing before the filter starts
    return std::nullopt;
  }
  bool against_gravity(double t_s, std::optional<double> error_rad) override {
    feed_until(t_s);
    return predictor_.check_tilt(t_s, error_rad);
  }
  std::optional<double> tilt_error_rad(double t_s, const Eigen::Isometry3d& cam_T_obj) override {
    feed_until(t_s);
    return predictor_.tilt_error_rad(t_s, cam_T_obj);
  }
  void replace_wrong_lock(double t_s, const Eigen::Isometry3d& cam_T_obj, double lock_since_s) override {
    feed_until(t_s);
    predictor_.replace_wrong_lock(t_s, cam_T_obj, lock_since_s);
  }
  std::optional<Upright> upright(double t_s) const override {
    const auto down_cam = predictor_.measured_down_cam(t_s);
    const auto down_obj = predictor_.learnt_down_obj();
    if (!down_cam || !down_obj) return std::nullopt;
    return Upright{-*down_cam, -*down_obj, options_.gravity_check.max_tilt_error_rad};
  }
  nlohmann::json frame_verdict() const override { return verdict_; }
  std::optional<fusion::VisionVerdict> verdict() const override { return first_verdict_; }
  std::unique_ptr<TrackPredictor> clone() const override { return std::make_unique<ImuPredictor>(*this); }
  nlohmann::json diagnostics() const override {
    const auto st = predictor_.status(last_good_t_s_);
    const auto& c = st.counters;
    nlohmann::json estimated = nullptr;
    if (estimator_) {
      estimated = {{"adopted", adopted_}, {"adopted_at_s", adopted_ ? adopted_at_s_ : -1.0}};
      if (const auto e = adopted_ ? std::optional(adopted_fit_) : estimator_->fit()) {
        estimated.update({{"offset_s", e->offset_s}, {"explained", e->explained}, {"pairs", e->pairs},
                          {"rate_rms_radps", e->rate_rms_radps}, {"outlier_pairs", e->outlier_pairs}});
        if (!adopted_) estimated["shortfall"] = estimator_->shortfall(*e);
      }
    }
    return {{"model", "imu"},
            {"imu_time_offset_s", offset_s_},
            {"imu_time_offset_sigma_s", predictor_.options().imu_time_offset_sigma_s},  // adopt() changes it
            {"imu_time_offset_estimate", estimated},
            {"imu_accepted", c.imu_accepted},
            {"imu_rejected", c.imu_non_finite + c.imu_saturated + c.imu_out_of_order + c.imu_duplicate},
            {"imu_saturated", c.imu_saturated},
            {"dropouts", c.dropouts},
            {"vision_applied", c.vision_applied},
            {"vision_initialised", c.vision_initialised},
            {"vision_gated", c.vision_gated},
            {"vision_too_old", c.vision_too_old},
            {"reinitialisations", c.reinitialisations},
            {"resumption_resets", c.resumption_resets},
            {"unaided_pose_floors", c.unaided_pose_floors},
            {"gravity_learnt", st.gravity_learnt},
            {"gravity_told", st.gravity_told},
            {"learnt_down_obj", learnt_down_json()},
            {"vision_against_gravity", c.vision_against_gravity},
            {"gravity_forgotten", c.gravity_forgotten},
            {"resets_after_loss", resets_},
            {"restarts_from_fallback", arbiter_.counters().fallback},
            {"weak_poses_after_loss", weak_reacquisitions_},
            {"weak_poses_unplaceable", weak_poses_unplaceable_},
            {"poses_against_carried_turn", against_carried_turn_},
            {"poses_against_start_pose", poses_against_start_},
            {"restarts_after_supported_gated", arbiter_.counters().supported_gated},
            {"restarts_after_agreeing_gated", arbiter_.counters().agreeing_gated},
            {"restarts_from_detection", detection_restarts_},
            {"vision_nis", nis_.to_json()},
            {"fallbacks_to_last_pose", fallbacks_},
            {"lost_frames", lost_}};
  }

 private:
  // The object's down the predictor learnt (unit, object frame), or null.
  nlohmann::json learnt_down_json() const {
    const auto d = predictor_.learnt_down_obj();
    if (!d) return nullptr;
    return nlohmann::json::array({d->x(), d->y(), d->z()});
  }
  static constexpr double kLostResetS = 1.0;
  // A line window's width (vision::WindowOptions::width_px): a prediction less sure than this
  // cannot place the windows.
  static constexpr double kUnplaceableSigmaPx = 40.0;
  static constexpr int kFitEveryFrames = 10;
  void feed_until(double t_s) {
    const auto& imu = *imu_;
    while (next_ < imu.size() && imu[next_].t_s - offset_s_ <= t_s) {
      fusion::ImuSample s;
      s.t_s = imu[next_].t_s;
      s.gyro_radps = imu[next_].gyro_radps;
      s.accel_mps2 = imu[next_].accel_mps2;
      predictor_.add_imu(s);
      carried_.add_gyro(s.t_s - offset_s_, s.gyro_radps);
      last_good_turned_.add_gyro(s.t_s - offset_s_, s.gyro_radps);
      // The estimator sees the gyro ahead of the camera by the search range, so every
      // candidate offset has samples.
      ++next_;
    }
    if (estimator_ && !adopted_)
      while (estimator_next_ < imu.size() && imu[estimator_next_].t_s <= t_s + kEstimatorLeadS) {
        estimator_->add_gyro(imu[estimator_next_].t_s, imu[estimator_next_].gyro_radps);
        ++estimator_next_;
      }
  }
  // Restart the filter on the estimated offset from this frame's pose: samples from just
  // before it are fed again on the new clock mapping.
  // Returns the frame's pose's verdict on the new filter.
  fusion::VisionResult adopt(const fusion::TimeOffsetEstimate& e, double t_s, const vision::FrameReport& report) {
    adopted_ = true;
    adopted_fit_ = e;
    adopted_at_s_ = t_s;
    offset_s_ = e.offset_s;
    fusion::PredictorOptions o = options_;
    o.imu_time_offset_s = offset_s_;
    o.imu_time_offset_sigma_s = kEstimatedOffsetSigmaS;
    auto p = fusion::Predictor::create(o);
    if (!p) return {};  // options were valid once; only the offset changed (BadInput)
    // The velocity, biases and gravity learnt so far carry over; only the clock changes.
    if (const auto motion = predictor_.state()) p->carry_motion(*motion, predictor_.covariance());
    p->carry_learnt_gravity(predictor_);
    p->carry_counters(predictor_);
    predictor_ = std::move(*p);
    // The gated poses the arbiter holds were measured against the filter on the old clock, as
    // after a loss's reset or a detection's restart (vision_arbiter.h: clear()).
    arbiter_.clear();
    const auto& imu = *imu_;
    next_ = 0;
    while (next_ < imu.size() && imu[next_].t_s - offset_s_ < t_s - options_.gravity_average_s - 0.05) ++next_;
    feed_until(t_s);
    const auto r = predictor_.add_vision(t_s, report.cam_T_obj, report.covariance);
    pending_init_ = r.verdict != fusion::VisionVerdict::Initialised && r.verdict != fusion::VisionVerdict::Applied;
    if (!pending_init_) {
      last_applied_t_s_ = t_s;
      carry(t_s);
    }
    init_t_s_ = t_s;
    return r;
  }
  // Whether a pose lies within three sigmas of the start pose (vision::initial_pose_covariance:
  // 1 cm and 1 deg per axis) in translation and in turn (the turn as far as an outline can tell:
  // not a body of revolution's about its axis).
  bool agrees_with_start(const Eigen::Isometry3d& cam_T_obj) const {
    const Eigen::Matrix<double, 6, 6> start_cov = vision::initial_pose_covariance();
    const double sigma_m = std::sqrt(start_cov(0, 0)), sigma_rad = std::sqrt(start_cov(3, 3));
    const double off_m = (cam_T_obj.translation() - start_pose_.translation()).norm();
    const double off_rad = vision::symmetric_turn_rad(cam_T_obj.linear(), start_pose_.linear(), symmetries_,
                                                      options_.gravity_check.free_turn_axis_obj);
    return off_m <= 3 * sigma_m && off_rad <= 3 * sigma_rad;
  }
  void note_good(double t_s, const Eigen::Isometry3d& cam_T_obj) {
    last_good_ = cam_T_obj;
    last_good_t_s_ = t_s;
    if (const auto x = predictor_.state()) gyro_bias_radps_ = x->gyro_bias_radps;
    last_good_turned_.set(t_s, cam_T_obj.linear(), 0, gyro_bias_radps_);
  }
  // The filter's orientation at t_s (just updated) is what the gyro carries from here.
  void carry(double t_s) { carried_.set_from(predictor_, t_s); }
  fusion::PredictorOptions options_;
  fusion::Predictor predictor_;
  const std::vector<vision::ImuRecord>* imu_;
  std::size_t next_ = 0;
  double offset_s_ = 0;
  double fx_px_ = 0;  // the camera's focal length (predicted_sigma_px)
  Eigen::Isometry3d last_good_;
  double last_good_t_s_ = 0, init_t_s_ = 0;
  double last_applied_t_s_ = -INFINITY;  // the filter's newest tracked pose (applied or seeding it); -inf: none since its seed or reset
  bool pending_init_ = false, reset_done_ = false;
  bool seeded_by_init_ = false;  // the filter's only pose so far is the start pose (init.csv)
  bool seed_given_ = true;       // the start pose is init.csv's, not a detection's
  Eigen::Isometry3d start_pose_ = Eigen::Isometry3d::Identity();  // init.csv's (agrees_with_start())
  int lost_ = 0, resets_ = 0, fallbacks_ = 0;
  int weak_reacquisitions_ = 0, weak_poses_unplaceable_ = 0, detection_restarts_ = 0, against_carried_turn_ = 0;
  int poses_against_start_ = 0;
  std::vector<Eigen::Isometry3d> symmetries_;  // the model's (vision/model_symmetry.h), for against_carried_turn()
  fusion::VisionArbiter arbiter_;  // who is wrong when vision and the filter disagree
  nlohmann::json verdict_;  // frame_verdict()
  std::optional<fusion::VisionVerdict> first_verdict_;  // verdict()
  vision::ConstantVelocity vision_only_;  // the second opinion when the IMU's prediction loses the object
  NisStats nis_;
  fusion::CarriedOrientation carried_;  // the orientation kept across a reset (carried_orientation())
  fusion::CarriedOrientation last_good_turned_;  // last_good_'s, turned by the gyro since (last_good_turned())
  Eigen::Vector3d gyro_bias_radps_ = Eigen::Vector3d::Zero();  // the filter's newest estimate
  // Offset estimation (auto).
  static constexpr double kEstimatorLeadS = 0.15;
  std::optional<fusion::TimeOffsetEstimator> estimator_;
  std::size_t estimator_next_ = 0;
  bool adopted_ = false;
  fusion::TimeOffsetEstimate adopted_fit_;
  double adopted_at_s_ = 0;
  int frames_since_fit_ = 0;
};

}  // namespace

std::expected<std::unique_ptr<TrackPredictor>, std::string> make_track_predictor(const vision::Sequence& seq, bool use_imu,
                                                                                 const ImuClock& clock,
                                                                                 const std::optional<Eigen::Vector3d>& object_up_obj) {
  if (use_imu) {
    if (!seq.has_imu()) return std::unexpected("--imu on: " + seq.dir() + " has no imu.csv");
    const std::optional<double>& imu_time_offset_s = clock.offset_s;
    if (imu_time_offset_s && !std::isfinite(*imu_time_offset_s)) return std::unexpected("--imu-time-offset-s must be finite");
    fusion::PredictorOptions options;
    options.mode = fusion::PredictorMode::ImuAided;
    options.imu_time_offset_s = imu_time_offset_s.value_or(0.0);
    // Disagreement is settled with the pose's support (fusion/vision_arbiter.h): a strongly
    // supported pose overrules the filter after three gated frames; a weak one only after half
    // a second of gated frames, when the filter is surely lost too.
    options.reinit_after_gated = 15;
    // Until the offset is estimated, every pose's time on the IMU clock is that uncertain.
    options.imu_time_offset_sigma_s = clock.sigma_s.value_or(imu_time_offset_s ? 0.0 : kUnknownOffsetSigmaS);
    // A body of revolution's poses turn freely about its axis: only the axis's tilt is checked.
    if (const auto axis = vision::find_revolution_axis(seq.model())) options.gravity_check.free_turn_axis_obj = axis->direction_obj.normalized();
    if (object_up_obj) options.gravity_check.told_down_obj = -*object_up_obj;
    auto predictor = fusion::Predictor::create(options);
    if (!predictor) return std::unexpected("--imu on: " + predictor.error());
    std::optional<fusion::TimeOffsetEstimator> estimator;
    if (!imu_time_offset_s) {
      auto e = fusion::TimeOffsetEstimator::create();
      if (!e) return std::unexpected("--imu on: " + e.error());
      estimator.emplace(std::move(*e));
    }
    return std::make_unique<ImuPredictor>(options, std::move(*predictor), seq, std::move(estimator));
  }
  return std::make_unique<ConstantVelocityPredictor>(seq.init().t_s, seq.init().cam_T_obj);
}

}  // namespace epichead::tools
