#pragma once
// What the line and ellipse RANSACs (fit_line.cpp, ellipse_fit.cpp) share: the sampler's
// generator and its seeding rule, the paper's Eq. 4 iteration count, the pool of distinct
// hypotheses, the "points of its own" test, and the final ordering and cut of the candidates.
// Private to vision/: the two fitters differ only in their model, sample size and distance.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace epichead::vision::ransac {

// xorshift32: deterministic and cheap, good enough for drawing sample indices. A local value in
// the fitting loop, so that its state stays in a register (as a member, every draw went through
// memory). Seed 0, the one state xorshift cannot leave, is taken as 1.
class Xorshift32 {
 public:
  explicit Xorshift32(std::uint32_t seed) : state_(seed != 0 ? seed : 1u) {}
  std::uint32_t next() {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }
  // An index in [0, n); n >= 1.
  int below(int n) { return static_cast<int>(next() % static_cast<std::uint32_t>(n)); }

 private:
  std::uint32_t state_;
};

// Eq. 4: N = log(1 - p) / log(1 - w^s) iterations give probability p of drawing one all-inlier
// sample of size s when a fraction w of the points are inliers; capped at `cap` (w near 0).
// `log_fail` is log(1 - p), computed once per fit (see log_failure).
inline int iterations_needed(double log_fail, double w, int sample_size, int cap) {
  double w_s = 1.0;
  for (int k = 0; k < sample_size; ++k) w_s *= w;
  const double miss = 1.0 - w_s;
  if (miss <= 0) return 1;
  if (miss >= 1) return cap;
  return static_cast<int>(std::min<double>(cap, std::ceil(log_fail / std::log(miss))));
}

// log(1 - p) for Eq. 4, with p kept below 1 (p = 1 would ask for infinitely many draws).
inline double log_failure(double probability) { return std::log(1.0 - std::clamp(probability, 0.0, 0.999999)); }

// Adds hypothesis h (any type with an int `support`) to a pool of distinct ones: one that
// `same(old, h)` calls the same model keeps the stronger of the two; a new one takes a free
// slot (the pool never grows past its reserved capacity, so nothing is allocated) or replaces
// the weakest when it is stronger.
template <class Hypothesis, class Same>
void pool_hypothesis(std::vector<Hypothesis>& pool, const Hypothesis& h, Same same) {
  for (Hypothesis& old : pool) {
    if (same(old, h)) {
      if (h.support > old.support) old = h;
      return;
    }
  }
  if (pool.size() < pool.capacity()) {
    pool.push_back(h);
    return;
  }
  auto weakest = std::min_element(pool.begin(), pool.end(),
                                  [](const Hypothesis& a, const Hypothesis& b) { return a.support < b.support; });
  if (weakest->support < h.support) *weakest = h;
}

// Strongest first (the order in which refined hypotheses are accepted).
template <class Hypothesis>
void sort_strongest_first(std::vector<Hypothesis>& pool) {
  std::sort(pool.begin(), pool.end(), [](const Hypothesis& a, const Hypothesis& b) { return a.support > b.support; });
}

// A weaker model must stand on points of its own, not on the inliers of stronger ones (two
// close parallel edges make diagonals, or several arcs make a false ellipse, through both sets
// of inliers). Counts the points of inliers[0, n) not yet claimed; when there are enough
// (>= min_exclusive), claims them all and returns true.
inline bool claim_own_points(const int* inliers, int n, std::vector<unsigned char>& claimed, double min_exclusive) {
  int exclusive = 0;
  for (int q = 0; q < n; ++q) exclusive += !claimed[inliers[q]];
  if (exclusive < min_exclusive) return false;
  for (int q = 0; q < n; ++q) claimed[inliers[q]] = 1;
  return true;
}

// Orders accepted candidates by support (a stable insertion sort over a handful: std::stable_sort
// would allocate a buffer) and keeps at most max_keep with support >= keep * the best's.
template <class Fit, class Ratio>
void sort_and_cut(std::vector<Fit>& candidates, int max_keep, Ratio keep) {
  for (std::size_t i = 1; i < candidates.size(); ++i)
    for (std::size_t j = i; j > 0 && candidates[j].support > candidates[j - 1].support; --j)
      std::swap(candidates[j], candidates[j - 1]);
  if (candidates.empty()) return;
  const int top = candidates.front().support;
  int kept = 0;
  while (kept < static_cast<int>(candidates.size()) && kept < max_keep && candidates[kept].support >= keep * top) ++kept;
  candidates.resize(kept);
}

}  // namespace epichead::vision::ransac
