#pragma once
// Ellipse fitting (EPIC step 4 for circles): the direct least-squares ellipse fit of Fitzgibbon,
// Pilu and Fisher (in the numerically stable form of Halir and Flusser), the conic through five
// points, and RANSAC over 5-point samples refined by the direct fit, keeping every candidate
// whose support is close to the best (as LineRansac does for lines). All in image pixels;
// points are centred and scaled internally for conditioning. Allocation-free after construction.
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/ellipse.h"

namespace epichead::vision {

// Direct least-squares ellipse through points (x[idx[k]], y[idx[k]]), k < n (n >= 5, not all on
// a line); nullopt when the points admit no ellipse. Always returns an ellipse when one exists
// (the constraint 4AC - B^2 = 1 of Fitzgibbon et al.), unlike a general conic fit.
std::optional<Ellipse> fit_ellipse_direct(const double* x_px, const double* y_px, const int* idx, int n);

// Conic coefficients through five points (x[idx[k]], y[idx[k]]), in coordinates centred on
// (ox, oy) and scaled by `scale`; nullopt for a degenerate sample.
std::optional<Conic> conic_through_5(const double* x, const double* y, const int* idx, double ox, double oy,
                                     double scale);

struct EllipseRansacOptions {
  double probability = 0.99;        // p of Eq. 4 with 5-point samples: N = log(1-p) / log(1-w^5)
  double inlier_distance_px = 1.5;  // Sampson distance of an inlier (edgel jitter plus the
                                    // curvature a 1-px-high tracker line cannot follow)
  double keep_ratio = 0.7;          // candidates with support >= keep_ratio * best are kept
  int max_candidates = 3;           // 1 = the single best ellipse
  int max_iterations = 300;         // cap on Eq. 4 (w near 0)
  int min_support = 6;              // one more than a sample: fewer is no ellipse
  double min_separation_px = 2.0;   // distinct candidates differ by this in centre or an axis
  double min_semi_minor_px = 3.0;   // smaller is no trackable ellipse
  double max_semi_major_px = 5000;  // larger is a near-line through a short arc
  // Bounds a caller sets from where the ellipse was expected (EllipseTracker): no bound by default.
  double min_semi_major_px = 0, max_semi_minor_px = 5000;
  // Start of the sampler's random sequence, re-applied for every fit (deterministic runs); the
  // same default and the same rule as RansacOptions::seed (0 means 1).
  std::uint32_t seed = 0x9E3779B9u;
};

// One fitted ellipse; its inliers are EllipseRansac::inliers()[inlier_begin, inlier_begin + support).
struct EllipseFit {
  Ellipse ellipse;
  int support = 0;
  int inlier_begin = 0;
};

class EllipseRansac {
 public:
  explicit EllipseRansac(const EllipseRansacOptions& options = {}, int max_points = 1024);
  const EllipseRansacOptions& options() const { return options_; }
  EllipseRansacOptions& options() { return options_; }
  // Fits points (x[i], y[i]), i < n; group[i] (e.g. the tracker line) keeps a sample's five
  // points in five different groups, so one line's cluster of edgels cannot make a sample.
  // Candidates come out sorted by support, best first. Deterministic (re-seeded per call).
  int fit(const double* x_px, const double* y_px, const int* group, int n);
  const std::vector<EllipseFit>& candidates() const { return candidates_; }
  const std::vector<int>& inliers() const { return inliers_; }
  int iterations() const { return iterations_; }

 private:
  struct Hypothesis { Ellipse ellipse; Conic k; int support = 0; };
  int count_support(const Conic& k_norm) const;
  bool plausible(const Ellipse& e) const;
  bool same_ellipse(const Ellipse& a, const Ellipse& b) const;
  void collect_inliers(const Ellipse& e);
  EllipseRansacOptions options_;
  int max_points_;
  int n_ = 0;
  double ox_ = 0, oy_ = 0, scale_ = 1;  // normalisation of the current point set
  std::vector<double> xn_, yn_;         // normalised coordinates
  const double* x_ = nullptr;
  const double* y_ = nullptr;
  int iterations_ = 0;
  std::vector<Hypothesis> hypotheses_;
  std::vector<EllipseFit> candidates_;
  std::vector<int> inliers_, scratch_;
  std::vector<unsigned char> claimed_;
};

}  // namespace epichead::vision
