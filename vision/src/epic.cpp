#include "epichead/vision/epic.h"
#include "epichead/vision/object_region.h"

#include <algorithm>
#include <cmath>

namespace epichead::vision {
namespace {

int max_edgels(const WindowOptions& w) {
  return std::max(w.max_rows, 2) * (std::clamp(w.width_px, 8, kMaxWindowWidth) / 2 + 1);
}

// Object-side weights of Eq. 2-3: 1 on the side(s) where the model puts the object, else 0.
float weight_left(ObjectSide side) { return side == ObjectSide::Right ? 0.0f : 1.0f; }
float weight_right(ObjectSide side) { return side == ObjectSide::Left ? 0.0f : 1.0f; }

// Mean and variance accumulator over cue channels.
struct Moments {
  std::array<double, kCueChannels> sum{}, sum_sq{};
  int n = 0;
  void add(const IntervalCues& c) {
    for (int k = 0; k < kCueChannels; ++k) { sum[k] += c.value[k]; sum_sq[k] += double(c.value[k]) * c.value[k]; }
    ++n;
  }
  double mean(int k) const { return sum[k] / n; }
  double var(int k) const { return std::max(0.0, sum_sq[k] / n - mean(k) * mean(k)); }
};

// The interval whose cues stand for side k (0: left, 1: right) of edgel i: its own, or with
// look-through, when that one is empty, the one beyond the neighbouring edgel of the same row.
int side_interval(const EdgelSet& set, const std::vector<IntervalCues>& intervals, int i, int k, bool look_through) {
  const Edgel& e = set.edgels[static_cast<std::size_t>(i)];
  const int own = e.left_interval + k;
  if (!look_through || own >= static_cast<int>(intervals.size()) || intervals[static_cast<std::size_t>(own)].valid) return own;
  const int neighbour = k == 0 ? i - 1 : i + 1;
  if (neighbour < set.row_begin[e.row] || neighbour >= set.row_begin[e.row + 1]) return own;
  return set.edgels[static_cast<std::size_t>(neighbour)].left_interval + k;
}

}  // namespace

void EpicResult::reserve(const WindowOptions& window, const RansacOptions& ransac) {
  edgels.reserve(window);
  const std::size_t n = static_cast<std::size_t>(max_edgels(window));
  reserve_touched(intervals, n + static_cast<std::size_t>(std::max(window.max_rows, 2)));
  reserve_touched(good, n);
  reserve_touched(candidates, 32);
  reserve_touched(inliers, n * static_cast<std::size_t>(std::max(ransac.max_candidates, 1)));
}

EpicDetector::EpicDetector(const EpicOptions& options, const WindowOptions& window)
    : options_(options), histograms_(options.cues), ransac_(options.ransac, max_edgels(window)) {
  const std::size_t n = static_cast<std::size_t>(max_edgels(window)) + std::max(window.max_rows, 2);
  agree_left_.resize(n);
  agree_right_.resize(n);
  fit_x_.resize(n);
  fit_s_.resize(n);
}

void EpicDetector::init_references(const LineWindow& window, ObjectSide side, FeatureReferences& refs) {
  const WindowGeometry& g = window.geometry();
  if (g.rows == 0) return;
  histograms_.prepare(window);
  const double centre = 0.5 * (g.cols - 1);
  const double margin = std::max(0.0f, options_.init_margin_px);
  const int left_end = static_cast<int>(std::floor(centre - margin)) + 1;  // x <= -margin
  const int right_begin = static_cast<int>(std::ceil(centre + margin));    // x >= +margin
  for (int k = 0; k < 2; ++k) {
    const bool used = k == 0 ? weight_left(side) > 0 : weight_right(side) > 0;
    if (!used) continue;
    Moments m;
    for (int r = 0; r < g.rows; ++r) {
      const IntervalCues c = k == 0 ? histograms_.interval(window, r, 0, left_end)
                                    : histograms_.interval(window, r, right_begin, g.cols);
      if (c.valid) m.add(c);
    }
    if (m.n == 0) continue;
    CueReference& ref = refs.side[k];
    for (int ch = 0; ch < kCueChannels; ++ch) {
      ref.mu[ch] = static_cast<float>(m.mean(ch));
      ref.sigma[ch] = std::max(static_cast<float>(std::sqrt(m.var(ch))), options_.cues.sigma_floor[ch]);
    }
  }
  refs.initialised = true;
}

void EpicDetector::detect(const LineWindow& window, ObjectSide side, const FeatureReferences& refs,
                          EpicMode mode, EpicResult& out, bool look_through, const OutlineEvidence& outline) {
  out.geometry = window.geometry();
  out.look_through = look_through && mode != EpicMode::Gradient;
  out.intervals.clear();
  out.good.clear();
  out.candidates.clear();
  out.inliers.clear();
  out.ransac_iterations = 0;
  find_edgels(window, options_.edgels, out.edgels);
  if (out.geometry.rows == 0) return;
  if (mode == EpicMode::Gradient) {
    select_good_gradient(out);
    fit(out, 1);
    return;
  }
  histograms_.prepare(window);
  const bool weigh = outline.active();
  histograms_.intervals(window, out.edgels, out.intervals, weigh || weight_left(side) > 0, weigh || weight_right(side) > 0);
  likelihoods(out, side, refs, window.colour());
  if (weigh) weigh_outline(out, outline);
  select_good_epic(out);
  fit(out, mode == EpicMode::EpicSingle ? 1 : options_.ransac.max_candidates);
}

void EpicDetector::likelihoods(EpicResult& out, ObjectSide side, const FeatureReferences& refs, bool colour) {
  // Eq. 2-3: l_k = (1/W) sum_i (w_left C_i(left interval) + w_right C_i(right interval)),
  // W = cues * (w_left + w_right). Each interval is compared once with each used reference.
  const float wl = weight_left(side), wr = weight_right(side);
  const int ni = static_cast<int>(out.intervals.size());
  if (wl > 0) cue_agreements(out.intervals.data(), ni, refs.side[0], colour, agree_left_.data());
  if (wr > 0) cue_agreements(out.intervals.data(), ni, refs.side[1], colour, agree_right_.data());
  const float inv_w = 1.0f / (static_cast<float>(cue_count(colour)) * (wl + wr));
  EdgelSet& set = out.edgels;
  const int n = static_cast<int>(set.edgels.size());
  auto agreement = [&](const std::vector<float>& agree, int i, int k) {
    return agree[static_cast<std::size_t>(side_interval(set, out.intervals, i, k, out.look_through))];
  };
  // A side of weight 0 adds exactly 0 (agreements are finite and >= 0), so a one-sided edge,
  // the common case, looks up only its object side.
  if (wl > 0 && wr > 0)
    for (int i = 0; i < n; ++i) set.edgels[i].likelihood = (agreement(agree_left_, i, 0) + agreement(agree_right_, i, 1)) * inv_w;
  else if (wl > 0)
    for (int i = 0; i < n; ++i) set.edgels[i].likelihood = agreement(agree_left_, i, 0) * inv_w;
  else
    for (int i = 0; i < n; ++i) set.edgels[i].likelihood = agreement(agree_right_, i, 1) * inv_w;
}

void EpicDetector::weigh_outline(EpicResult& out, const OutlineEvidence& outline) const {
  EdgelSet& set = out.edgels;
  const int n = static_cast<int>(set.edgels.size());
  for (int i = 0; i < n; ++i) {
    Edgel& e = set.edgels[static_cast<std::size_t>(i)];
    const std::int8_t outer = outline.outer_side[e.row];
    if (outer == 0) continue;
    const IntervalCues& beyond = out.intervals[static_cast<std::size_t>(side_interval(set, out.intervals, i, outer > 0 ? 1 : 0, out.look_through))];
    e.likelihood *= 1.0f - outline.region->object_probability(beyond);
  }
}

void EpicDetector::select_good_epic(EpicResult& out) const {
  const EdgelSet& set = out.edgels;
  const float ratio = std::clamp(options_.row_keep_ratio, 0.0f, 1.0f);
  for (int r = 0; r < set.rows; ++r) {
    const int b = set.row_begin[r], e = set.row_begin[r + 1];
    float best = 0;
    for (int k = b; k < e; ++k) best = std::max(best, set.edgels[k].likelihood);
    if (best <= 1e-6f) continue;  // no edgel of this row looks like the object at all
    for (int k = b; k < e; ++k)
      if (set.edgels[k].likelihood >= ratio * best) out.good.push_back(k);
  }
}

void EpicDetector::select_good_gradient(EpicResult& out) const {
  const EdgelSet& set = out.edgels;
  float strongest = 0;
  for (const Edgel& e : set.edgels) strongest = std::max(strongest, std::fabs(e.gradient));
  const float strong = options_.strong_gradient_ratio * strongest;
  for (int r = 0; r < set.rows; ++r) {
    int pick = -1;
    float nearest = 1e30f;
    for (int k = set.row_begin[r]; k < set.row_begin[r + 1]; ++k) {
      const Edgel& e = set.edgels[k];
      if (std::fabs(e.gradient) >= strong && std::fabs(e.x_px) < nearest) { nearest = std::fabs(e.x_px); pick = k; }
    }
    if (pick >= 0) out.good.push_back(pick);
  }
}

void EpicDetector::fit(EpicResult& out, int max_candidates) {
  const int n = static_cast<int>(out.good.size());
  for (int k = 0; k < n; ++k) {
    const Edgel& e = out.edgels.edgels[out.good[k]];
    fit_x_[k] = e.x_px;
    fit_s_[k] = e.s_px;
  }
  const WindowGeometry& g = out.geometry;
  ransac_.options().max_candidates = max_candidates;
  const float s_first = static_cast<float>(g.s_of_row(0)), s_last = static_cast<float>(g.s_of_row(g.rows - 1));
  ransac_.fit(fit_x_.data(), fit_s_.data(), n, s_first, s_last);
  out.ransac_iterations = ransac_.iterations();
  const auto& idx = ransac_.inliers();
  for (const LineFit& f : ransac_.candidates()) {
    LineCandidate c;
    c.line = f.line;
    // End points at the segment's ends (s = 0 and s = length), so that a line tracked from its
    // previous result keeps its length instead of shrinking by a row each frame.
    c.a_px = g.to_image(f.line.x_at(0.0f), 0.0);
    c.b_px = g.to_image(f.line.x_at(static_cast<float>(g.length_px)), g.length_px);
    c.support = f.support;
    c.inlier_begin = static_cast<int>(out.inliers.size());
    for (int k = 0; k < f.support; ++k) out.inliers.push_back(out.good[idx[f.inlier_begin + k]]);
    out.candidates.push_back(c);
  }
}

void EpicDetector::update_references(const EpicResult& result, const LineCandidate& selected, ObjectSide side,
                                     FeatureReferences& refs) const {
  const float a = std::clamp(options_.update_rate, 0.0f, 1.0f);
  for (int k = 0; k < 2; ++k) {
    const bool used = k == 0 ? weight_left(side) > 0 : weight_right(side) > 0;
    if (!used) continue;
    Moments m;
    for (int q = 0; q < selected.support; ++q) {
      // k = 0: the interval on the left, 1: on the right (the ones the likelihood used)
      const int j = side_interval(result.edgels, result.intervals, result.inliers[selected.inlier_begin + q], k,
                                  result.look_through);
      if (j < static_cast<int>(result.intervals.size()) && result.intervals[j].valid) m.add(result.intervals[j]);
    }
    if (m.n < 3) continue;
    CueReference& ref = refs.side[k];
    for (int ch = 0; ch < kCueChannels; ++ch) {
      const float floor = options_.cues.sigma_floor[ch];
      const double var_obs = std::max(m.var(ch), double(floor) * floor);
      ref.mu[ch] = static_cast<float>((1 - a) * ref.mu[ch] + a * m.mean(ch));
      const double var = (1 - a) * double(ref.sigma[ch]) * ref.sigma[ch] + a * var_obs;
      ref.sigma[ch] = std::max(static_cast<float>(std::sqrt(var)), floor);
    }
  }
}

}  // namespace epichead::vision
