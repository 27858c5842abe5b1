#include "epichead/vision/line_tracker.h"
#include "epichead/vision/object_region.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace epichead::vision {

LineTracker::LineTracker(const LineTrackerOptions& options)
    : options_(options), window_(options.window), detector_(options.epic, options.window) {
  outer_side_.reserve(static_cast<std::size_t>(std::max(options.window.max_rows, 2)));
}

void LineTracker::reset() {
  for (LineFeature& f : features_) {
    f.refs = {};
    f.has_previous = false;
    f.visible = f.found = false;
    f.selected = -1;
  }
}

void LineTracker::reserve(int edges) {
  grow_to(edges);
  for (LineFeature& f : features_) reserve_buffers(f);
}

void LineTracker::grow_to(int edges) {
  if (edges <= static_cast<int>(features_.size())) return;
  features_.resize(static_cast<std::size_t>(edges));
  longest_.resize(features_.size());
}

void LineTracker::reserve_buffers(LineFeature& f) const {
  if (f.reserved) return;
  f.result.reserve(options_.window, options_.epic.ransac);
  f.reserved = true;
}

void LineTracker::track(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement) {
  detect(image, visible, placement);
  for (LineFeature& f : features_) {
    if (!f.visible) continue;
    if (f.result.found()) accept(f.edge, 0);
    else reject(f.edge);
  }
}

void LineTracker::detect(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement) {
  int max_edge = -1;
  for (const VisibleEdge& e : visible.edges) max_edge = std::max(max_edge, e.edge);
  grow_to(max_edge + 1);  // first frame (warm-up), unless reserve() came first
  std::fill(longest_.begin(), longest_.end(), -1);
  for (int i = 0; i < static_cast<int>(visible.edges.size()); ++i) {
    const VisibleEdge& e = visible.edges[i];
    if (e.edge < 0 || e.kind == EdgeKind::CylinderSilhouette) continue;  // cylinders index another table
    int& best = longest_[e.edge];
    if (best < 0 || (e.b_px - e.a_px).squaredNorm() > (visible.edges[best].b_px - visible.edges[best].a_px).squaredNorm())
      best = i;
  }
  for (int k = 0; k < static_cast<int>(features_.size()); ++k) {
    LineFeature& f = features_[k];
    f.edge = k;
    f.visible = f.found = false;
    f.selected = -1;
    if (longest_[k] < 0) { f.has_previous = false; continue; }  // hidden: re-project when it returns
    detect_one(image, visible.edges[longest_[k]], placement, options_.look_through && !has_close_parallel(visible, k), f);
  }
}

// Another visible edge within parallel_reach_deg of this one's direction, less than half a window
// width from its midpoint and alongside it: a window on this edge could see it as the neighbour.
bool LineTracker::has_close_parallel(const VisibleModel& visible, int edge) const {
  const VisibleEdge& me = visible.edges[static_cast<std::size_t>(longest_[static_cast<std::size_t>(edge)])];
  const Eigen::Vector2d mid = 0.5 * (me.a_px + me.b_px);
  const Eigen::Vector2d dir = (me.b_px - me.a_px).normalized();
  const double reach_px = 0.5 * options_.window.width_px;
  const double max_sin = std::sin(options_.parallel_reach_deg * std::numbers::pi / 180.0);
  for (std::size_t j = 0; j < longest_.size(); ++j) {
    if (static_cast<int>(j) == edge || longest_[j] < 0) continue;
    const VisibleEdge& other = visible.edges[static_cast<std::size_t>(longest_[j])];
    const Eigen::Vector2d d = other.b_px - other.a_px;
    const double length = d.norm();
    if (!(length > 0)) continue;
    const Eigen::Vector2d od = d / length;
    if (std::abs(dir.x() * od.y() - dir.y() * od.x()) > max_sin) continue;  // not parallel
    const Eigen::Vector2d rel = mid - other.a_px;
    const double along = rel.dot(od), across = std::abs(rel.x() * od.y() - rel.y() * od.x());
    if (across < reach_px && along > -reach_px && along < length + reach_px) return true;
  }
  return false;
}

void LineTracker::detect_one(const WindowImage& image, const VisibleEdge& piece, WindowPlacement placement,
                             bool look_through, LineFeature& f) {
  reserve_buffers(f);
  f.side = piece.side;
  f.piece = piece;
  if (!f.refs.initialised && options_.mode != EpicMode::Gradient) {
    // References from the object side of the projected edge, whatever the placement.
    if (window_.sample(image, piece.a_px, piece.b_px)) detector_.init_references(window_, piece.side, f.refs);
  }
  Eigen::Vector2d a = piece.a_px, b = piece.b_px;
  if (placement == WindowPlacement::Previous && f.has_previous) {
    a = f.previous_a_px;
    b = f.previous_b_px;
    // Keep the projection's direction so that its ObjectSide applies.
    if ((b - a).dot(piece.b_px - piece.a_px) < 0) std::swap(a, b);
  }
  f.window_a_px = a;
  f.window_b_px = b;
  if (!window_.sample(image, a, b)) {
    f.result.candidates.clear();
    f.has_previous = false;
    return;
  }
  f.visible = true;
  OutlineEvidence outline;
  if (outline_region_ && outline_region_->ready()) {
    const WindowGeometry& g = window_.geometry();
    outer_side_.resize(static_cast<std::size_t>(g.rows));  // within the reserved capacity
    for (int r = 0; r < g.rows; ++r)
      outer_side_[static_cast<std::size_t>(r)] = outline_region_->outer_side(g.to_image(0, g.s_of_row(r)), g.across);
    outline = {outline_region_, outer_side_.data()};
  }
  detector_.detect(window_, piece.side, f.refs, options_.mode, f.result, look_through, outline);
  // Candidates are sorted by support: drop the tail too weak to be a line of this window.
  const int rows = window_.geometry().rows;
  const int need = std::max(options_.epic.ransac.min_support,
                            static_cast<int>(std::ceil(options_.min_support_ratio * static_cast<float>(rows))));
  auto& cands = f.result.candidates;
  while (!cands.empty() && cands.back().support < need) cands.pop_back();
  if (!cands.empty()) f.selected = 0;
}

void LineTracker::accept(int edge, int candidate) {
  LineFeature& f = features_[static_cast<std::size_t>(edge)];
  if (!f.visible || candidate < 0 || candidate >= static_cast<int>(f.result.candidates.size())) {
    reject(edge);
    return;
  }
  const LineCandidate& c = f.result.candidates[static_cast<std::size_t>(candidate)];
  f.found = true;
  f.selected = candidate;
  f.has_previous = true;
  f.previous_a_px = c.a_px;
  f.previous_b_px = c.b_px;
  if (options_.mode != EpicMode::Gradient) detector_.update_references(f.result, c, f.side, f.refs);
}

void LineTracker::reject(int edge) {
  LineFeature& f = features_[static_cast<std::size_t>(edge)];
  f.found = false;
  f.selected = -1;
  f.has_previous = false;  // lost: the next window goes back to the projection (recovery)
}

}  // namespace epichead::vision
