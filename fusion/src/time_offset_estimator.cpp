#include "epichead/fusion/time_offset_estimator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "epichead/geometry/so3.h"

namespace epichead::fusion {

namespace {

// Drops the oldest entries of a full store in one move (no allocation: the capacity stays).
template <typename T>
void drop_front(std::vector<T>& v, std::size_t n) {
  v.erase(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(std::min(n, v.size())));
}

// Poses kept for pairing: a span and a gap's worth at up to 400 poses a second.
constexpr std::size_t kRecentCapacity = 96;

}  // namespace

std::expected<TimeOffsetEstimator, std::string> TimeOffsetEstimator::create(const TimeOffsetOptions& o) {
  const double values[] = {o.max_offset_s, o.step_s, o.window_s, o.imu_rate_hz, o.max_pair_gap_s, o.min_rate_rms_radps};
  for (double v : values)
    if (!std::isfinite(v) || !(v > 0)) return std::unexpected("time offset estimator: ranges, step, window and rates must be positive");
  if (!std::isfinite(o.pair_span_s) || o.pair_span_s < 0 || o.pair_span_s > o.window_s)
    return std::unexpected("time offset estimator: pair_span_s must be within [0, window_s]");
  if (o.step_s > o.max_offset_s) return std::unexpected("time offset estimator: step_s larger than max_offset_s");
  if (!(o.outlier_factor > 1) || !std::isfinite(o.outlier_factor))
    return std::unexpected("time offset estimator: outlier_factor must be finite and above 1");
  if (o.min_pairs < 3) return std::unexpected("time offset estimator: min_pairs must be at least 3");
  if (!o.cam_R_imu.allFinite()) return std::unexpected("time offset estimator: cam_R_imu not finite");
  return TimeOffsetEstimator(o);
}

TimeOffsetEstimator::TimeOffsetEstimator(const TimeOffsetOptions& o) : options_(o) {
  const auto gyro_capacity = static_cast<std::size_t>((o.window_s + 2 * o.max_offset_s + 1.0) * o.imu_rate_hz * 2);
  t_.reserve(gyro_capacity);
  integral_.reserve(gyro_capacity);
  pairs_.reserve(static_cast<std::size_t>(o.window_s * 400) + 16);  // up to 400 poses/s
  costs_.reserve(static_cast<std::size_t>(2 * std::floor(o.max_offset_s / o.step_s) + 1));
  use_.reserve(pairs_.capacity());
  residuals_.reserve(pairs_.capacity());
  recent_.reserve(kRecentCapacity);
}

void TimeOffsetEstimator::add_gyro(double t_imu_s, const Eigen::Vector3d& gyro_radps) {
  if (!std::isfinite(t_imu_s) || !gyro_radps.allFinite() || (!t_.empty() && !(t_imu_s > t_.back()))) return;
  const Eigen::Vector3d g = options_.cam_R_imu * gyro_radps;
  if (t_.size() == t_.capacity()) {
    const std::size_t n = t_.size() / 2;
    drop_front(t_, n);
    drop_front(integral_, n);
  }
  // The rate is integrated with the trapezoid rule: the integral's differences give the mean
  // rate over any interval between samples.
  const Eigen::Vector3d next = t_.empty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(integral_.back() + 0.5 * (last_gyro_ + g) * (t_imu_s - t_.back()));
  t_.push_back(t_imu_s);
  integral_.push_back(next);
  last_gyro_ = g;
}

void TimeOffsetEstimator::add_pose(double t_cam_s, const Eigen::Isometry3d& cam_T_obj) {
  if (!std::isfinite(t_cam_s) || !cam_T_obj.matrix().allFinite()) return;
  if (!recent_.empty() && !(t_cam_s > recent_.back().t_s)) return;
  const Eigen::Matrix3d R = cam_T_obj.linear();
  if (!recent_.empty() && t_cam_s - recent_.back().t_s > options_.max_pair_gap_s) recent_.clear();  // the chain broke
  // The newest earlier pose at least pair_span_s before this one.
  for (auto it = recent_.rbegin(); it != recent_.rend(); ++it) {
    if (t_cam_s - it->t_s < options_.pair_span_s) continue;
    // cam_a_R_cam_b = R_a R_b^T = exp(w dt), w in camera axes.
    const Eigen::Vector3d w = geometry::so3_log(it->R * R.transpose()) / (t_cam_s - it->t_s);
    if (pairs_.size() == pairs_.capacity()) drop_front(pairs_, pairs_.size() / 2);
    pairs_.push_back({it->t_s, t_cam_s, w});
    break;
  }
  // Only poses that a later one may still pair with are kept.
  std::size_t stale = 0;
  while (stale < recent_.size() && recent_[stale].t_s < t_cam_s - options_.pair_span_s - options_.max_pair_gap_s) ++stale;
  // More poses than kRecentCapacity within a span and a gap (over 400 a second): the oldest go.
  if (recent_.size() - stale >= kRecentCapacity) stale = recent_.size() - kRecentCapacity + 1;
  drop_front(recent_, stale);
  recent_.push_back({t_cam_s, R});
  // Pairs older than the window are not used.
  std::size_t old = 0;
  while (old < pairs_.size() && pairs_[old].t1_s < t_cam_s - options_.window_s) ++old;
  if (old > 0) drop_front(pairs_, old);
}

bool TimeOffsetEstimator::mean_rate(double a, double b, Eigen::Vector3d& out) const {
  if (t_.size() < 2 || a < t_.front() || b > t_.back() || !(b > a)) return false;
  auto at = [&](double t) {
    const auto it = std::upper_bound(t_.begin(), t_.end(), t);
    const std::size_t i = static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(it - t_.begin(), 1, static_cast<std::ptrdiff_t>(t_.size() - 1)));
    const double f = (t - t_[i - 1]) / (t_[i] - t_[i - 1]);
    return Eigen::Vector3d(integral_[i - 1] + f * (integral_[i] - integral_[i - 1]));
  };
  out = (at(b) - at(a)) / (b - a);
  return true;
}

bool TimeOffsetEstimator::usable(const Pair& p) const {
  // Every candidate offset must find the pair's shifted interval inside the stored gyro span,
  // so that all candidates are scored on the same pairs.
  return t_.size() >= 2 && p.t0_s - options_.max_offset_s >= t_.front() && p.t1_s + options_.max_offset_s <= t_.back();
}

double TimeOffsetEstimator::cost(double offset_s) const {
  double sum = 0;
  Eigen::Vector3d g;
  for (std::size_t i = 0; i < pairs_.size(); ++i)
    if (use_[i] && mean_rate(pairs_[i].t0_s + offset_s, pairs_[i].t1_s + offset_s, g)) sum += (pairs_[i].rate - g).squaredNorm();
  return sum;
}

double TimeOffsetEstimator::best_offset(double& best_cost, bool& at_edge) const {
  const int steps = static_cast<int>(std::floor(options_.max_offset_s / options_.step_s));
  costs_.resize(static_cast<std::size_t>(2 * steps + 1));  // within the capacity reserved at create()
  int best_k = -steps;
  for (int k = -steps; k <= steps; ++k) {
    costs_[static_cast<std::size_t>(k + steps)] = cost(k * options_.step_s);
    if (costs_[static_cast<std::size_t>(k + steps)] < costs_[static_cast<std::size_t>(best_k + steps)]) best_k = k;
  }
  at_edge = best_k == -steps || best_k == steps;
  best_cost = costs_[static_cast<std::size_t>(best_k + steps)];
  double offset = best_k * options_.step_s;
  if (!at_edge) {
    const double cm = costs_[static_cast<std::size_t>(best_k + steps - 1)], cp = costs_[static_cast<std::size_t>(best_k + steps + 1)];
    const double curvature = cm - 2 * best_cost + cp;
    if (curvature > 0) offset += 0.5 * (cm - cp) / curvature * options_.step_s;
  }
  return offset;
}

std::optional<TimeOffsetEstimate> TimeOffsetEstimator::fit() const {
  use_.assign(pairs_.size(), 0);  // within the capacity reserved at create()
  int usable_pairs = 0;
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    use_[i] = usable(pairs_[i]);
    usable_pairs += use_[i];
  }
  if (usable_pairs < 3) return std::nullopt;
  TimeOffsetEstimate e;
  double best = 0;
  e.offset_s = best_offset(best, e.at_search_edge);

  // Second pass without the outlier pairs: residual norms at the first fit against their median.
  residuals_.clear();
  Eigen::Vector3d g;
  for (std::size_t i = 0; i < pairs_.size(); ++i)
    if (use_[i] && mean_rate(pairs_[i].t0_s + e.offset_s, pairs_[i].t1_s + e.offset_s, g)) residuals_.push_back((pairs_[i].rate - g).norm());
  if (residuals_.size() >= 3) {
    const auto mid = residuals_.begin() + static_cast<std::ptrdiff_t>(residuals_.size() / 2);
    std::nth_element(residuals_.begin(), mid, residuals_.end());
    const double limit = options_.outlier_factor * *mid;
    auto outlier = [&](std::size_t i) {
      return !mean_rate(pairs_[i].t0_s + e.offset_s, pairs_[i].t1_s + e.offset_s, g) || (pairs_[i].rate - g).norm() > limit;
    };
    int outliers = 0;
    for (std::size_t i = 0; i < pairs_.size(); ++i) outliers += use_[i] && outlier(i);
    if (outliers > 0 && usable_pairs - outliers >= 3) {
      for (std::size_t i = 0; i < pairs_.size(); ++i)
        if (use_[i] && outlier(i)) use_[i] = 0;
      e.outlier_pairs = outliers;
      e.offset_s = best_offset(best, e.at_search_edge);
    }
  }

  // Excitation and explained variation over the pairs of the final fit.
  int n = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double sq = 0;
  for (std::size_t i = 0; i < pairs_.size(); ++i) {
    if (!use_[i]) continue;
    mean += pairs_[i].rate;
    sq += pairs_[i].rate.squaredNorm();
    ++n;
  }
  if (n < 3) return std::nullopt;
  mean /= n;
  double var = 0;
  for (std::size_t i = 0; i < pairs_.size(); ++i)
    if (use_[i]) var += (pairs_[i].rate - mean).squaredNorm();
  e.pairs = n;
  e.rate_rms_radps = std::sqrt(sq / n);
  e.explained = var > 0 ? 1.0 - best / var : 0.0;
  return e;
}

std::optional<TimeOffsetEstimate> TimeOffsetEstimator::estimate() const {
  auto e = fit();
  if (!e || !shortfall(*e).empty()) return std::nullopt;
  return e;
}

std::string TimeOffsetEstimator::shortfall(const TimeOffsetEstimate& e) const {
  std::string out;
  char part[96];
  const auto add = [&] {
    if (!out.empty()) out += "; ";
    out += part;
  };
  if (e.pairs < options_.min_pairs) {
    std::snprintf(part, sizeof part, "%d pose pairs, %d needed", e.pairs, options_.min_pairs);
    add();
  }
  if (e.rate_rms_radps < options_.min_rate_rms_radps) {
    std::snprintf(part, sizeof part, "the camera turned %.2f rad/s RMS, %.2f needed", e.rate_rms_radps,
                  options_.min_rate_rms_radps);
    add();
  }
  if (e.explained < options_.min_explained) {
    std::snprintf(part, sizeof part, "the fit explained %.0f %% of the turn, %.0f %% needed", 100 * e.explained,
                  100 * options_.min_explained);
    add();
  }
  if (e.at_search_edge) {
    std::snprintf(part, sizeof part, "the best offset lay at the search range's edge (+-%.0f ms)",
                  1e3 * options_.max_offset_s);
    add();
  }
  return out;
}

}  // namespace epichead::fusion
