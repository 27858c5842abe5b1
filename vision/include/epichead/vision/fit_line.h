#pragma once
// Line fitting (EPIC step 4) in window coordinates, where the line is near-vertical and
// x = m s + c is well conditioned (x across, s along, both in image pixels). RANSAC over 2-point
// samples with the iteration count of the paper's Eq. 4, N = log(1 - p) / log(1 - w^2), updated
// as the inlier ratio w improves; every hypothesis whose support is close to the best is kept as
// a candidate, and each is refined by total least squares on its inliers. A weaker candidate
// must also be close to the best on points no stronger candidate has claimed (else it is a
// diagonal through the inliers of stronger lines, not a line of its own).
#include <cstdint>
#include <vector>

namespace epichead::vision {

// x = m s + c in window pixels.
struct WindowLine {
  float m = 0, c = 0;
  float x_at(float s_px) const { return m * s_px + c; }
  // Perpendicular distance of (x, s) from the line.
  float distance(float x_px, float s_px) const;
};

struct RansacOptions {
  double probability = 0.99;       // p of Eq. 4: chance that every kept candidate was sampled
  float inlier_distance_px = 1.0f; // a point within this of the line supports it
  // Candidates with support >= keep_ratio * best are kept. Eq. 4 is evaluated with
  // w = keep_ratio * (best inlier ratio), so such weaker lines are also sampled with probability p.
  float keep_ratio = 0.7f;
  int max_candidates = 4;          // 1 = the single best line only
  int max_iterations = 500;        // cap on Eq. 4 (w near 0)
  int min_support = 3;             // fewer inliers than this is no line at all
  float min_separation_px = 2.0f;  // distinct candidates differ by this much at either window end
  // Start of the sampler's random sequence, re-applied for every window (deterministic runs).
  // Another seed draws other point pairs: how much a result moves with it shows how much it
  // hangs on the draw (docs/epic.md, sixth pass). 0, the one state xorshift cannot leave, means 1.
  std::uint32_t seed = 0x9E3779B9u;
};

// One fitted line with its support; inliers are indices into the points given to fit(), stored
// in LineRansac::inliers() at [inlier_begin, inlier_begin + support).
struct LineFit {
  WindowLine line;
  int support = 0;
  int inlier_begin = 0;
};

// Total least squares line through points idx[0..n) of (x, s); n >= 2 with distinct points.
WindowLine fit_line_tls(const float* x_px, const float* s_px, const int* idx, int n);

// RANSAC with candidate keeping. Buffers are reserved once for max_points; fit() then
// allocates nothing. Deterministic: the random generator is re-seeded on every call.
class LineRansac {
 public:
  explicit LineRansac(const RansacOptions& options = {}, int max_points = 1024);
  const RansacOptions& options() const { return options_; }
  RansacOptions& options() { return options_; }
  // Fits points (x_px[i], s_px[i]), i < n; the window spans s in [s_begin, s_end] (for the
  // separation test). Candidates come out sorted by support, best first. Returns their count.
  int fit(const float* x_px, const float* s_px, int n, float s_begin, float s_end);
  const std::vector<LineFit>& candidates() const { return candidates_; }
  const std::vector<int>& inliers() const { return inliers_; }
  int iterations() const { return iterations_; }  // RANSAC iterations of the last fit

 private:
  struct Hypothesis { WindowLine line; int support = 0; };
  int count_support(const WindowLine& line, const float* x, const float* s, int n) const;
  bool same_line(const WindowLine& a, const WindowLine& b) const;
  RansacOptions options_;
  int max_points_;
  float s_begin_ = 0, s_end_ = 0;
  int iterations_ = 0;
  std::vector<Hypothesis> hypotheses_;
  std::vector<LineFit> candidates_;
  std::vector<int> inliers_, scratch_;
  std::vector<unsigned char> claimed_;  // per point: inlier of an accepted candidate
};

}  // namespace epichead::vision
