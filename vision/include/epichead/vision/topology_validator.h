#pragma once
// Validation by model topology (EPIC step 5): the candidates of the line windows are checked
// against the relations the model says their edges have, and majority voting selects one
// candidate per feature.
//
//  - Connectivity: at each model junction, for every pair of edges meeting there that are
//    visible with the junction in view, every combination of their candidates is intersected;
//    a combination whose intersection is near the projected junction is scored by the edgels
//    found in small windows warped along each candidate just before the intersection (real
//    edges of a corner reach the corner; clutter lines rarely end there). The best combination
//    gets the relation's vote, and its intersection becomes the junction's image position.
//  - Parallelism: for pairs of model-parallel edges, each candidate pair is compared with the
//    projected expectation by the angle between the two lines and the normal distance from the
//    first line's centre to the second; the best pair gets the relation's vote.
//
// A feature's candidate with the most votes wins (ties: the one with more RANSAC support).
// The work is bounded: at most max_candidates^2 combinations per relation and a cap on the
// parallel partners per edge. Allocation-free after the first frame.
#include <vector>

#include <Eigen/Core>

#include "epichead/vision/cao_model.h"
#include "epichead/vision/edgels.h"
#include "epichead/vision/line_tracker.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

namespace epichead::vision {

struct ValidationOptions {
  // Junction windows: this long (px) along each candidate, ending gap_px before the intersection,
  // junction_width_px across. An edgel within edgel_tolerance_px of the candidate counts for its row.
  double junction_window_px = 10.0;
  double junction_gap_px = 2.0;
  int junction_width_px = 12;
  double edgel_tolerance_px = 1.5;
  // An intersection farther than this from the projected junction is no combination at all: the
  // windows are 40 px wide, so a candidate can be at most 20 px off; corners move with them.
  double max_junction_shift_px = 30.0;
  // Below this evidence (fraction of junction-window rows with an edgel on both candidates) a
  // combination gets no vote: the two lines do not visibly meet.
  double min_junction_evidence = 0.5;
  // Parallelism: expected spreads of the angle difference and of the normal distance. The
  // prediction is off by a few px and a fraction of a degree between frames; these are a few times that.
  double parallel_angle_sigma_rad = 0.03;
  double parallel_distance_sigma_px = 2.0;
  double parallel_gate = 9.0;       // squared normalised error above which a pair gets no vote
  int max_parallel_partners = 3;    // per edge, the nearest parallel edges (in the image) only
};

// One junction located in the image by intersecting selected candidates.
struct ValidatedJunction {
  int vertex = -1;  // index into CadModel::vertices
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  int lines = 0;           // pairwise intersections averaged into px
  double evidence = 0;     // mean junction-window evidence of those intersections
};

struct ValidationResult {
  std::vector<int> selected;       // per model edge: chosen candidate, -1 when none
  std::vector<int> votes;          // per model edge: votes of the chosen candidate
  std::vector<int> relations;      // per model edge: relations it took part in
  std::vector<ValidatedJunction> junctions;
  int junction_relations = 0, parallel_relations = 0, combinations = 0;
  int changed = 0;                 // features whose choice differs from RANSAC's best
};

class TopologyValidator {
 public:
  TopologyValidator(const CadModel& model, const ValidationOptions& options = {});
  const ValidationOptions& options() const { return options_; }
  // Votes over the candidates of `features` (a LineTracker's, after detect()) and selects one
  // candidate per visible feature with candidates.
  void validate(const WindowImage& image, const std::vector<LineFeature>& features, ValidationResult& out);

 private:
  // The stages of validate(), in order.
  void vote_junctions(const WindowImage& image, const std::vector<LineFeature>& features, int edges,
                      ValidationResult& out);
  void vote_parallels(const std::vector<LineFeature>& features, int edges, ValidationResult& out);
  void select_majority(const std::vector<LineFeature>& features, int edges, ValidationResult& out) const;
  void locate_junctions(const WindowImage& image, const std::vector<LineFeature>& features, int edges,
                        ValidationResult& out);
  void vote(int edge, int candidate);
  double junction_evidence(const WindowImage& image, const Eigen::Vector2d& corner_px,
                           const Eigen::Vector2d& into_edge, const LineCandidate& c);
  const CadModel* model_;
  ValidationOptions options_;
  LineWindow window_;
  EdgelSet edgels_;
  // Per model edge and candidate: vote counts, flattened [edge * kMaxCandidates + candidate].
  std::vector<int> votes_;
  // Scratch per junction: pairwise intersections of the winning combinations.
  std::vector<Eigen::Vector2d> corner_sum_;
  std::vector<int> corner_count_;
  std::vector<double> corner_evidence_;
  std::vector<std::pair<double, int>> partners_;  // scratch: (image distance, partner edge)
  std::vector<std::vector<int>> parallel_of_;      // per edge: its model-parallel edges (built once)
};

}  // namespace epichead::vision
