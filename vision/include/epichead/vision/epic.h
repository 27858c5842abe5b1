#pragma once
// EPIC on one line window (Vincze et al., "Edge Projected Integration of Cues"): edgels, interval
// cues, the likelihood of each edgel against the feature's reference, the good edgels, RANSAC
// candidates, and the update of the reference from the selected candidate. See docs/epic.md.
#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/cues.h"
#include "epichead/vision/edgels.h"
#include "epichead/vision/fit_line.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/visibility.h"

namespace epichead::vision {

// What chooses the edgels that are fitted (for measuring the gain of each step).
enum class EpicMode {
  Gradient,    // classic: per row the strong gradient nearest the prediction, no cues, one line
  EpicSingle,  // EPIC likelihoods, only the best RANSAC candidate
  Epic,        // EPIC likelihoods, every candidate close to the best
};

// Per-feature cue references, one per side of the line: [0] = ObjectSide::Left (low window
// columns), [1] = Right. Only the object side(s) are used; Both keeps two since the faces differ.
struct FeatureReferences {
  std::array<CueReference, 2> side{};
  bool initialised = false;
};

struct EpicOptions {
  EdgelOptions edgels;
  CueOptions cues;
  RansacOptions ransac;
  // Good edgels (EPIC mode): in each row, the edgels whose likelihood is at least this fraction
  // of the row's best. The paper keeps the most likely edgel per row with no threshold (= 1.0);
  // 0.8 also keeps near-ties, which is what lets two close parallel edges both reach RANSAC.
  float row_keep_ratio = 0.8f;
  // Gradient mode: a maximum is "strong" if |g| >= this fraction of the window's largest |g|.
  float strong_gradient_ratio = 0.5f;
  // Exponential forgetting of the reference update: mu <- (1 - a) mu + a * observed.
  float update_rate = 0.3f;
  // Reference initialisation leaves this many px either side of the projected line out
  // (prediction error plus edge blur), and takes the rest of the object-side half-rows.
  float init_margin_px = 3.0f;
};

class ObjectRegion;

// What the object's region (object_region.h) says about one window: per window row, the side
// that leaves the object there (+1 the high columns, -1 the low ones, 0 not on the outline).
// On outline rows an edgel whose interval on that side looks like the object is unlikely to be
// the object's edge, however well its object side agrees with the references.
struct OutlineEvidence {
  const ObjectRegion* region = nullptr;
  const std::int8_t* outer_side = nullptr;
  bool active() const { return region != nullptr && outer_side != nullptr; }
};

// A candidate line of one window, in window and image coordinates.
struct LineCandidate {
  WindowLine line;                             // x = m s + c in the window
  Eigen::Vector2d a_px = Eigen::Vector2d::Zero();  // on the line at s = 0 (the window's a end)
  Eigen::Vector2d b_px = Eigen::Vector2d::Zero();  // on the line at s = length (the b end)
  int support = 0;                             // inlier good edgels
  int inlier_begin = 0;                        // inliers at EpicResult::inliers[begin, begin + support)
};

// Everything EPIC found in one window; buffers reserved once and reused.
struct EpicResult {
  WindowGeometry geometry;
  EdgelSet edgels;
  std::vector<IntervalCues> intervals;  // per row: edgels + 1 intervals, see CueHistograms
  std::vector<int> good;                // indices into edgels.edgels, fitted by RANSAC
  std::vector<LineCandidate> candidates;  // best support first
  std::vector<int> inliers;             // indices into edgels.edgels
  int ransac_iterations = 0;
  // detect() let an edgel whose own object-side interval is empty take the cues of the interval
  // beyond its neighbour (see EpicDetector::detect); update_references reads the same intervals.
  bool look_through = false;
  bool found() const { return !candidates.empty(); }
  void reserve(const WindowOptions& window, const RansacOptions& ransac);
};

// Runs EPIC on windows; holds all per-window scratch, so detect() allocates nothing once the
// result buffers are reserved.
class EpicDetector {
 public:
  explicit EpicDetector(const EpicOptions& options = {}, const WindowOptions& window = {});
  const EpicOptions& options() const { return options_; }

  // Initial references from the object side(s) of a window placed on the projected edge: per
  // row the mode over the half-row beyond init_margin_px, then mean and deviation over rows.
  void init_references(const LineWindow& window, ObjectSide side, FeatureReferences& refs);
  // Edgels, cues, likelihoods, good edgels and candidates of `window`. Gradient mode ignores refs.
  // look_through: where the interval between an edgel and its neighbour is empty (edgels at most
  // 3 columns apart: a thin border or strip along the edge, narrower than the edge margins), the
  // edgel's cue on that side is the interval beyond the neighbour, instead of no evidence. For
  // an edge with no other model edge close and parallel to it (the caller knows the model); two
  // close parallel edges would otherwise look alike and no longer be told apart.
  // outline: weighs each outline row's edgels by how little their outer interval looks like the
  // object (EPIC modes; the outer intervals are then computed too).
  void detect(const LineWindow& window, ObjectSide side, const FeatureReferences& refs,
              EpicMode mode, EpicResult& out, bool look_through = false, const OutlineEvidence& outline = {});
  // Re-estimates the object-side references from the interval cues of the candidate's inlier
  // edgels (exponential forgetting, sigma floored). No-op with fewer than 3 valid intervals.
  void update_references(const EpicResult& result, const LineCandidate& selected, ObjectSide side,
                         FeatureReferences& refs) const;

 private:
  void likelihoods(EpicResult& out, ObjectSide side, const FeatureReferences& refs, bool colour);
  void weigh_outline(EpicResult& out, const OutlineEvidence& outline) const;
  void select_good_epic(EpicResult& out) const;
  void select_good_gradient(EpicResult& out) const;
  void fit(EpicResult& out, int max_candidates);
  EpicOptions options_;
  CueHistograms histograms_;
  LineRansac ransac_;
  std::vector<float> agree_left_, agree_right_;  // per interval: sum_i C_i vs each side's reference
  std::vector<float> fit_x_, fit_s_;             // good edgel coordinates for RANSAC
};

}  // namespace epichead::vision
