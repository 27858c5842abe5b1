#include "epichead/vision/topology_validator.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace epichead::vision {
namespace {

// Candidates beyond this many per feature are not validated (RANSAC keeps max_candidates, 4 by
// default); bounds the combinations per relation to 64.
constexpr int kMaxValidated = 8;

WindowOptions junction_window(const ValidationOptions& o) {
  WindowOptions w;
  w.width_px = std::clamp(o.junction_width_px, 8, kMaxWindowWidth);
  w.max_rows = std::max(2, static_cast<int>(std::ceil(o.junction_window_px)) + 1);
  return w;
}

// Intersection of the infinite lines through a0-a1 and b0-b1; false when nearly parallel (the
// point would be ill-defined) or non-finite.
bool intersect(const Eigen::Vector2d& a0, const Eigen::Vector2d& a1, const Eigen::Vector2d& b0,
               const Eigen::Vector2d& b1, Eigen::Vector2d& out) {
  const Eigen::Vector2d da = a1 - a0, db = b1 - b0;
  const double cross = da.x() * db.y() - da.y() * db.x();
  const double norms = da.norm() * db.norm();
  if (!(norms > 0) || std::abs(cross) < std::sin(5.0 * std::numbers::pi / 180.0) * norms) return false;
  const Eigen::Vector2d w = b0 - a0;
  const double t = (w.x() * db.y() - w.y() * db.x()) / cross;
  out = a0 + t * da;
  return out.allFinite();
}

// Direction of a line folded to [0, pi).
double line_angle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  double t = std::atan2(b.y() - a.y(), b.x() - a.x());
  if (t < 0) t += std::numbers::pi;
  if (t >= std::numbers::pi) t -= std::numbers::pi;
  return t;
}

// Difference of two folded line angles, wrapped to (-pi/2, pi/2].
double angle_difference(double from, double to) {
  double d = to - from;
  while (d > std::numbers::pi / 2) d -= std::numbers::pi;
  while (d <= -std::numbers::pi / 2) d += std::numbers::pi;
  return d;
}

// Signed distance of point p from the line a->b (positive on the side of (dy, -dx)).
double signed_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double len = d.norm();
  if (!(len > 0)) return 0;
  return ((p - a).x() * d.y() - (p - a).y() * d.x()) / len;
}

// Where the junction vertex `v` lies on the projected piece of edge `e`, and the unit direction
// from it into the edge. False when that end of the edge is clipped or hidden.
bool junction_end(const ModelEdge& edge, const LineFeature& f, int v, Eigen::Vector2d& corner, Eigen::Vector2d& into) {
  constexpr double kEnd = 1e-6;
  const VisibleEdge& p = f.piece;
  if (edge.v0 == v && p.s0 <= kEnd) {
    corner = p.a_px;
    into = p.b_px - p.a_px;
  } else if (edge.v1 == v && p.s1 >= 1 - kEnd) {
    corner = p.b_px;
    into = p.a_px - p.b_px;
  } else {
    return false;
  }
  const double n = into.norm();
  if (!(n > 1e-9)) return false;
  into /= n;
  return true;
}

bool usable(const LineFeature& f) { return f.visible && !f.result.candidates.empty(); }

int validated_count(const LineFeature& f) {
  return std::min(kMaxValidated, static_cast<int>(f.result.candidates.size()));
}

}  // namespace

TopologyValidator::TopologyValidator(const CadModel& model, const ValidationOptions& options)
    : model_(&model), options_(options), window_(junction_window(options)) {
  edgels_.reserve(junction_window(options));
  const std::size_t edges = model.edges.size();
  votes_.assign(edges * kMaxValidated, 0);
  corner_sum_.assign(model.vertices.size(), Eigen::Vector2d::Zero());
  corner_count_.assign(model.vertices.size(), 0);
  corner_evidence_.assign(model.vertices.size(), 0.0);
  parallel_of_.resize(edges);
  for (const ParallelPair& p : model.parallel_pairs) {
    if (p.edge_a < 0 || p.edge_b < 0 || p.edge_a >= static_cast<int>(edges) || p.edge_b >= static_cast<int>(edges)) continue;
    parallel_of_[static_cast<std::size_t>(p.edge_a)].push_back(p.edge_b);
    parallel_of_[static_cast<std::size_t>(p.edge_b)].push_back(p.edge_a);
  }
  std::size_t most = 0;
  for (const auto& list : parallel_of_) most = std::max(most, list.size());
  partners_.reserve(most);
}

double TopologyValidator::junction_evidence(const WindowImage& image, const Eigen::Vector2d& corner_px,
                                            const Eigen::Vector2d& into_edge, const LineCandidate& c) {
  // The candidate's own direction, oriented into the edge like the projection.
  Eigen::Vector2d dir = c.b_px - c.a_px;
  const double n = dir.norm();
  if (!(n > 1e-9)) return 0;
  dir /= n;
  if (dir.dot(into_edge) < 0) dir = -dir;
  const Eigen::Vector2d a = corner_px + options_.junction_gap_px * dir;
  const Eigen::Vector2d b = a + options_.junction_window_px * dir;
  if (!window_.sample(image, a, b)) return 0;
  find_edgels(window_, EdgelOptions{}, edgels_);
  const int rows = window_.geometry().rows;
  if (rows <= 0) return 0;
  int supported = 0;
  for (int r = 0; r < rows; ++r) {
    for (int k = edgels_.row_begin[r]; k < edgels_.row_begin[r + 1]; ++k) {
      if (std::abs(edgels_.edgels[k].x_px) <= options_.edgel_tolerance_px) {
        ++supported;
        break;
      }
    }
  }
  return static_cast<double>(supported) / rows;
}

void TopologyValidator::validate(const WindowImage& image, const std::vector<LineFeature>& features, ValidationResult& out) {
  const int edges = static_cast<int>(std::min(features.size(), model_->edges.size()));
  out.selected.assign(model_->edges.size(), -1);
  out.votes.assign(model_->edges.size(), 0);
  out.relations.assign(model_->edges.size(), 0);
  out.junctions.clear();
  out.junction_relations = out.parallel_relations = out.combinations = out.changed = 0;
  std::fill(votes_.begin(), votes_.end(), 0);
  vote_junctions(image, features, edges, out);
  vote_parallels(features, edges, out);
  select_majority(features, edges, out);
  locate_junctions(image, features, edges, out);
}

void TopologyValidator::vote(int edge, int candidate) {
  ++votes_[static_cast<std::size_t>(edge) * kMaxValidated + candidate];
}

// Connectivity: every pair of usable edges at every junction in view; the combination with the
// best evidence votes for its two candidates.
void TopologyValidator::vote_junctions(const WindowImage& image, const std::vector<LineFeature>& features, int edges,
                                       ValidationResult& out) {
  const CadModel& model = *model_;
  for (const ModelJunction& j : model.junctions) {
    const int m = static_cast<int>(j.edges.size());
    for (int x = 0; x < m; ++x) {
      const int ea = j.edges[static_cast<std::size_t>(x)];
      if (ea >= edges || !usable(features[ea])) continue;
      Eigen::Vector2d corner_a, into_a;
      if (!junction_end(model.edges[ea], features[ea], j.vertex, corner_a, into_a)) continue;
      for (int y = x + 1; y < m; ++y) {
        const int eb = j.edges[static_cast<std::size_t>(y)];
        if (eb >= edges || !usable(features[eb])) continue;
        Eigen::Vector2d corner_b, into_b;
        if (!junction_end(model.edges[eb], features[eb], j.vertex, corner_b, into_b)) continue;
        const Eigen::Vector2d projected = 0.5 * (corner_a + corner_b);
        int best_a = -1, best_b = -1;
        double best_evidence = options_.min_junction_evidence;
        const auto& ca_list = features[ea].result.candidates;
        const auto& cb_list = features[eb].result.candidates;
        for (int ca = 0; ca < validated_count(features[ea]); ++ca) {
          for (int cb = 0; cb < validated_count(features[eb]); ++cb) {
            ++out.combinations;
            const LineCandidate& A = ca_list[static_cast<std::size_t>(ca)];
            const LineCandidate& B = cb_list[static_cast<std::size_t>(cb)];
            Eigen::Vector2d p;
            if (!intersect(A.a_px, A.b_px, B.a_px, B.b_px, p)) continue;
            if ((p - projected).norm() > options_.max_junction_shift_px) continue;
            const double ev_a = junction_evidence(image, p, into_a, A);
            if (ev_a < options_.min_junction_evidence) continue;
            const double ev_b = junction_evidence(image, p, into_b, B);
            const double ev = std::min(ev_a, ev_b);  // both lines must reach the corner
            // Ties go to the stronger RANSAC support (lower indices come first).
            if (ev > best_evidence || (best_a < 0 && ev >= best_evidence)) {
              best_evidence = ev;
              best_a = ca;
              best_b = cb;
            }
          }
        }
        ++out.junction_relations;
        ++out.relations[ea];
        ++out.relations[eb];
        if (best_a < 0) continue;
        vote(ea, best_a);
        vote(eb, best_b);
      }
    }
  }
}

// Parallelism: each usable edge with its nearest usable model-parallel partners; the pair of
// candidates whose angle and distance best match the projection's votes.
void TopologyValidator::vote_parallels(const std::vector<LineFeature>& features, int edges, ValidationResult& out) {
  for (int ea = 0; ea < edges; ++ea) {
    if (!usable(features[ea])) continue;
    const VisibleEdge& pa = features[ea].piece;
    const Eigen::Vector2d mid_a = 0.5 * (pa.a_px + pa.b_px);
    partners_.clear();
    for (int eb : parallel_of_[static_cast<std::size_t>(ea)]) {
      if (eb >= edges || eb <= ea || !usable(features[eb])) continue;  // each pair once, from its lower edge
      const VisibleEdge& pb = features[eb].piece;
      partners_.emplace_back((0.5 * (pb.a_px + pb.b_px) - mid_a).norm(), eb);
    }
    const int keep = std::min(static_cast<int>(partners_.size()), std::max(0, options_.max_parallel_partners));
    std::partial_sort(partners_.begin(), partners_.begin() + keep, partners_.end());
    for (int k = 0; k < keep; ++k) {
      const int eb = partners_[static_cast<std::size_t>(k)].second;
      const VisibleEdge& pb = features[eb].piece;
      const double angle_expected = angle_difference(line_angle(pa.a_px, pa.b_px), line_angle(pb.a_px, pb.b_px));
      const double dist_expected = signed_distance(mid_a, pb.a_px, pb.b_px);
      double best_cost = options_.parallel_gate;
      int best_a = -1, best_b = -1;
      const auto& ca_list = features[ea].result.candidates;
      const auto& cb_list = features[eb].result.candidates;
      for (int ca = 0; ca < validated_count(features[ea]); ++ca) {
        const LineCandidate& A = ca_list[static_cast<std::size_t>(ca)];
        const Eigen::Vector2d mid = 0.5 * (A.a_px + A.b_px);
        const double angle_a = line_angle(A.a_px, A.b_px);
        for (int cb = 0; cb < validated_count(features[eb]); ++cb) {
          ++out.combinations;
          const LineCandidate& B = cb_list[static_cast<std::size_t>(cb)];
          const double da = (angle_difference(angle_a, line_angle(B.a_px, B.b_px)) - angle_expected) / options_.parallel_angle_sigma_rad;
          const double dd = (signed_distance(mid, B.a_px, B.b_px) - dist_expected) / options_.parallel_distance_sigma_px;
          const double cost = da * da + dd * dd;
          if (cost < best_cost) { best_cost = cost; best_a = ca; best_b = cb; }
        }
      }
      ++out.parallel_relations;
      ++out.relations[ea];
      ++out.relations[eb];
      if (best_a < 0) continue;
      vote(ea, best_a);
      vote(eb, best_b);
    }
  }
}

// Majority per feature; ties go to the stronger RANSAC candidate (lower index).
void TopologyValidator::select_majority(const std::vector<LineFeature>& features, int edges, ValidationResult& out) const {
  for (int e = 0; e < edges; ++e) {
    if (!usable(features[e])) continue;
    int best = 0;
    const int* v = &votes_[static_cast<std::size_t>(e) * kMaxValidated];
    for (int c = 1; c < validated_count(features[e]); ++c)
      if (v[c] > v[best]) best = c;
    out.selected[e] = best;
    out.votes[e] = v[best];
    out.changed += best != 0;
  }
}

// Junction positions from the selected candidates: every pair at a junction whose two selected
// lines intersect near the projection and visibly reach the corner.
void TopologyValidator::locate_junctions(const WindowImage& image, const std::vector<LineFeature>& features, int edges,
                                         ValidationResult& out) {
  const CadModel& model = *model_;
  std::fill(corner_sum_.begin(), corner_sum_.end(), Eigen::Vector2d::Zero());
  std::fill(corner_count_.begin(), corner_count_.end(), 0);
  std::fill(corner_evidence_.begin(), corner_evidence_.end(), 0.0);
  for (const ModelJunction& j : model.junctions) {
    const int m = static_cast<int>(j.edges.size());
    for (int x = 0; x < m; ++x) {
      const int ea = j.edges[static_cast<std::size_t>(x)];
      if (ea >= edges || out.selected[ea] < 0) continue;
      Eigen::Vector2d corner_a, into_a;
      if (!junction_end(model.edges[ea], features[ea], j.vertex, corner_a, into_a)) continue;
      for (int y = x + 1; y < m; ++y) {
        const int eb = j.edges[static_cast<std::size_t>(y)];
        if (eb >= edges || out.selected[eb] < 0) continue;
        Eigen::Vector2d corner_b, into_b;
        if (!junction_end(model.edges[eb], features[eb], j.vertex, corner_b, into_b)) continue;
        const LineCandidate& A = features[ea].result.candidates[static_cast<std::size_t>(out.selected[ea])];
        const LineCandidate& B = features[eb].result.candidates[static_cast<std::size_t>(out.selected[eb])];
        Eigen::Vector2d p;
        if (!intersect(A.a_px, A.b_px, B.a_px, B.b_px, p)) continue;
        if ((p - 0.5 * (corner_a + corner_b)).norm() > options_.max_junction_shift_px) continue;
        const double ev = std::min(junction_evidence(image, p, into_a, A), junction_evidence(image, p, into_b, B));
        if (ev < options_.min_junction_evidence) continue;
        corner_sum_[static_cast<std::size_t>(j.vertex)] += p;
        corner_count_[static_cast<std::size_t>(j.vertex)] += 1;
        corner_evidence_[static_cast<std::size_t>(j.vertex)] += ev;
      }
    }
  }
  for (std::size_t v = 0; v < corner_count_.size(); ++v) {
    if (corner_count_[v] == 0) continue;
    const double n = corner_count_[v];
    out.junctions.push_back({static_cast<int>(v), corner_sum_[v] / n, corner_count_[v], corner_evidence_[v] / n});
  }
}

}  // namespace epichead::vision
