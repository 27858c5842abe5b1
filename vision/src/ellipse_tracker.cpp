#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/object_region.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>

namespace epichead::vision {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

ObjectSide object_side(RimSide side) {
  // Tracker-line columns run from inside to outside: the inside is ObjectSide::Left.
  switch (side) {
    case RimSide::Inside: return ObjectSide::Left;
    case RimSide::Outside: return ObjectSide::Right;
    case RimSide::Both:
    case RimSide::Model: break;
  }
  return ObjectSide::Both;
}

// The detector only computes edgels, cues, likelihoods and good edgels for tracker lines: its
// line RANSAC is switched off (no window holds that many points), the ellipse is fitted here.
EpicOptions without_line_fit(EpicOptions o) {
  o.ransac.min_support = INT_MAX;
  o.ransac.max_iterations = 0;
  return o;
}

WindowOptions window_options(const EllipseTrackerOptions& o) {
  return WindowOptions{std::clamp(o.width_px, 8, kMaxWindowWidth), std::max(o.lines, 3) + 2};
}

// The tracker line `spacings` spacings beyond an arc end, one spacing at a time (each follows
// the local curvature).
TrackerLine extension_line(const Ellipse& on, double end_polar_rad, double step_px, int spacings, int direction) {
  TrackerLine l = tracker_line_beyond(on, end_polar_rad, step_px, direction);
  for (int k = 1; k < spacings; ++k) l = tracker_line_beyond(on, l.polar_rad, step_px, direction);
  return l;
}

double polar_about(const Eigen::Vector2d& centre, const Eigen::Vector2d& p) {
  return std::atan2(p.y() - centre.y(), p.x() - centre.x());
}

}  // namespace

EllipseTracker::EllipseTracker(const EllipseTrackerOptions& options)
    : options_(options),
      window_(std::max(options.lines, 3) + 2, options.width_px),
      detector_(without_line_fit(options.epic), window_options(options)),
      ransac_(options.ransac, window_options(options).max_rows * (window_options(options).width_px / 2 + 1)) {
  options_.lines = std::max(options_.lines, 3);
  const int max_points = window_options(options_).max_rows * (window_options(options_).width_px / 2 + 1);
  px_x_.resize(static_cast<std::size_t>(max_points));
  px_y_.resize(static_cast<std::size_t>(max_points));
  outer_side_.reserve(static_cast<std::size_t>(options_.lines) + 2);
  px_row_.resize(static_cast<std::size_t>(max_points));
}

void EllipseTracker::reset() {
  for (EllipseFeature& f : features_) {
    f.refs = {};
    f.has_previous = false;
    f.visible = f.found = f.weak = false;
    f.selected = -1;
    f.arc = {};
    f.has_circle_arc = false;
    f.extension_begin = f.extension_end = 1;
  }
}

EllipseFeature& EllipseTracker::feature(int circle) {
  if (circle >= static_cast<int>(features_.size())) features_.resize(static_cast<std::size_t>(circle) + 1);  // warm-up
  EllipseFeature& f = features_[static_cast<std::size_t>(circle)];
  f.circle = circle;
  if (!f.reserved) {
    const WindowOptions w = window_options(options_);
    f.result.reserve(w, options_.epic.ransac);
    f.lines.reserve(static_cast<std::size_t>(w.max_rows));
    f.row_hit.reserve(static_cast<std::size_t>(w.max_rows));
    f.candidates.reserve(16);
    f.candidate_inliers.reserve(static_cast<std::size_t>(w.max_rows) * (w.width_px / 2 + 1) * 4);
    f.reserved = true;
  }
  return f;
}

void EllipseTracker::track(const WindowImage& image, const VisibleModel& visible, WindowPlacement placement) {
  int max_circle = -1;
  for (const VisibleEllipse& e : visible.ellipses) max_circle = std::max(max_circle, e.circle);
  if (max_circle >= 0) feature(max_circle);
  for (EllipseFeature& f : features_) f.visible = f.found = f.weak = false;
  for (EllipseFeature& f : features_) {
    bool seen = false;
    for (const VisibleEllipse& e : visible.ellipses) seen = seen || e.circle == f.circle;
    if (!seen) { f.has_previous = false; f.selected = -1; }  // hidden: re-projected when it returns
  }
  for (const VisibleEllipse& v : visible.ellipses) {
    if (v.circle < 0) continue;
    Ellipse projection;
    projection.centre_px = v.centre_px;
    projection.semi_major_px = v.semi_major_px;
    projection.semi_minor_px = v.semi_minor_px;
    projection.angle_rad = v.angle_rad;
    track_one(image, v.circle, projection, placement, v.side, &v.circle_to_px);
  }
}

bool EllipseTracker::place(const WindowImage& image, EllipseFeature& f, const Ellipse& on, const EllipseArc& arc) {
  const int n = options_.lines;
  f.placed_on = on;
  f.placed_arc = arc;
  f.lines.resize(static_cast<std::size_t>(n) + 2);  // within the reserved capacity
  double step = 0;
  if (arc.full()) {
    step = spread_tracker_lines(on, arc, n, f.lines.data());
    f.lines.resize(static_cast<std::size_t>(n));
    f.arc_row_begin = 0;
    f.arc_row_end = n;
  } else {
    step = spread_tracker_lines(on, arc, n, f.lines.data() + 1);
    f.lines[0] = extension_line(on, arc.begin_rad, step, f.extension_begin, -1);
    f.lines[static_cast<std::size_t>(n) + 1] = extension_line(on, arc.begin_rad + arc.span_rad, step, f.extension_end, +1);
    f.arc_row_begin = 1;
    f.arc_row_end = n + 1;
  }
  if (!(step > 0)) { f.lines.clear(); return false; }
  return window_.sample(image, f.lines.data(), static_cast<int>(f.lines.size()));
}

void EllipseTracker::track_one(const WindowImage& image, int circle, const Ellipse& projection, WindowPlacement placement,
                               ObjectSide model_side, const Eigen::Matrix3d* circle_to_px) {
  if (circle < 0) return;
  EllipseFeature& f = feature(circle);
  f.visible = f.found = f.weak = false;
  f.selected = -1;
  f.candidates.clear();
  f.candidate_inliers.clear();
  f.row_hit.clear();
  f.side = options_.side == RimSide::Model ? model_side : object_side(options_.side);
  if (!projection.valid()) { f.has_previous = false; return; }
  if (!f.refs.initialised && options_.mode != EpicMode::Gradient) {
    // References from both sides of the projected contour, whatever the placement.
    if (place(image, f, projection, EllipseArc{})) detector_.init_references(window_.window(), f.side, f.refs);
  }
  Ellipse on = projection;
  EllipseArc arc;
  if (placement == WindowPlacement::Previous && f.has_previous) {
    on = f.ellipse;
    arc = f.arc;
  } else if (placement == WindowPlacement::ProjectionOnArc && f.has_previous) {
    // The arc kept in the circle's own angle lands on the same part of the rim under the new
    // pose. Polar angles about last frame's fitted centre do not carry over to the projection:
    // an ellipse fitted to a partly hidden rim is often 10-20 px off the projection's centre,
    // which put the arc's lines onto the occluder.
    arc = circle_to_px && f.has_circle_arc ? polar_arc_of(*circle_to_px, projection, f.circle_arc) : f.arc;
  }
  if (!place(image, f, on, arc)) {
    f.has_previous = false;
    f.arc = {};
    f.has_circle_arc = false;
    f.extension_begin = f.extension_end = 1;
    return;
  }
  f.visible = true;
  OutlineEvidence outline;
  if (outline_region_ && outline_region_->ready()) {
    outer_side_.resize(f.lines.size());  // within the reserved capacity
    for (std::size_t r = 0; r < f.lines.size(); ++r) outer_side_[r] = outline_region_->outer_side(f.lines[r].centre_px, f.lines[r].normal);
    outline = {outline_region_, outer_side_.data()};
  }
  detector_.detect(window_.window(), f.side, f.refs, options_.mode, f.result, false, outline);
  fit(f);
  update_arc(f, circle_to_px);
  if (f.found && options_.mode != EpicMode::Gradient) {
    // Re-estimate the references from the intervals beside the selected ellipse's inliers.
    const EllipseFit& c = f.candidates[static_cast<std::size_t>(f.selected)];
    f.result.inliers.assign(f.candidate_inliers.begin() + c.inlier_begin,
                            f.candidate_inliers.begin() + c.inlier_begin + c.support);
    update_.support = c.support;
    update_.inlier_begin = 0;
    detector_.update_references(f.result, update_, f.side, f.refs);
  }
}

Eigen::Vector2d EllipseTracker::edgel_px(const EllipseFeature& f, int edgel) const {
  const Edgel& e = f.result.edgels.edgels[static_cast<std::size_t>(edgel)];
  const TrackerLine& l = f.lines[static_cast<std::size_t>(e.row)];
  return l.centre_px + static_cast<double>(e.x_px) * l.normal;
}

bool EllipseTracker::plausible(const EllipseFeature& f, const Ellipse& e) const {
  // The new contour must cross every arc line inside its window: an ellipse fitted to a short
  // arc can otherwise swing far from where any line looked (it has no support there).
  const double half = 0.5 * (window_.width_px() - 1);
  const Conic k = e.conic();
  for (int r = f.arc_row_begin; r < f.arc_row_end; ++r) {
    const Eigen::Vector2d& p = f.lines[static_cast<std::size_t>(r)].centre_px;
    // Sampson distance |Q| / |grad Q| <= half, squared.
    const double q = conic_value(k, p.x(), p.y());
    const double gx = 2 * k[0] * p.x() + k[1] * p.y() + k[3], gy = k[1] * p.x() + 2 * k[2] * p.y() + k[4];
    if (!(q * q <= half * half * (gx * gx + gy * gy))) return false;
  }
  return true;
}

void EllipseTracker::fit(EllipseFeature& f) {
  int n = 0;
  for (int k : f.result.good) {
    const Eigen::Vector2d p = edgel_px(f, k);
    px_x_[static_cast<std::size_t>(n)] = p.x();
    px_y_[static_cast<std::size_t>(n)] = p.y();
    px_row_[static_cast<std::size_t>(n)] = f.result.edgels.edgels[static_cast<std::size_t>(k)].row;
    ++n;
  }
  // Between frames an axis changes by less than half a tracker line, or the lines miss it anyway;
  // and by a fraction of the ellipse's size (a change of distance or tilt): without that bound
  // a small ellipse half hidden by a board was fitted through the board's straight edge.
  EllipseRansacOptions& ro = ransac_.options();
  const double half = 0.5 * window_.width_px();
  ro.max_candidates = options_.mode == EpicMode::Epic ? options_.ransac.max_candidates : 1;
  const double change = std::min(half, std::max(options_.min_axis_change_px, options_.max_axis_change * f.placed_on.semi_major_px));
  ro.max_semi_major_px = std::min(options_.ransac.max_semi_major_px, f.placed_on.semi_major_px + change);
  ro.min_semi_major_px = std::max(options_.ransac.min_semi_major_px, f.placed_on.semi_major_px - change);
  ro.min_semi_minor_px = std::max(options_.ransac.min_semi_minor_px, f.placed_on.semi_minor_px - change);
  ro.max_semi_minor_px = std::min(options_.ransac.max_semi_minor_px, f.placed_on.semi_minor_px + change);
  ransac_.fit(px_x_.data(), px_y_.data(), px_row_.data(), n);
  f.ransac_iterations = ransac_.iterations();
  for (const EllipseFit& fit : ransac_.candidates()) {
    EllipseFit c = fit;
    c.inlier_begin = static_cast<int>(f.candidate_inliers.size());
    for (int q = 0; q < fit.support; ++q)
      f.candidate_inliers.push_back(f.result.good[static_cast<std::size_t>(ransac_.inliers()[static_cast<std::size_t>(fit.inlier_begin + q)])]);
    f.candidates.push_back(c);
  }
  // Select the best-supported plausible candidate with inliers on enough tracker lines
  // (topology validation may later choose among the candidates instead).
  const int arc_lines = f.arc_row_end - f.arc_row_begin;
  const int need = std::max(std::max(options_.ransac.min_support, 5),
                            static_cast<int>(std::ceil(options_.min_support_ratio * static_cast<float>(arc_lines))));
  f.row_hit.assign(f.lines.size(), 0);
  for (int c = 0; c < static_cast<int>(f.candidates.size()); ++c) {
    const EllipseFit& cand = f.candidates[static_cast<std::size_t>(c)];
    if (!plausible(f, cand.ellipse)) continue;
    std::fill(f.row_hit.begin(), f.row_hit.end(), 0);
    for (int q = 0; q < cand.support; ++q)
      f.row_hit[static_cast<std::size_t>(f.result.edgels.edgels[static_cast<std::size_t>(f.candidate_inliers[static_cast<std::size_t>(cand.inlier_begin + q)])].row)] = 1;
    int rows_hit = 0;
    for (unsigned char h : f.row_hit) rows_hit += h;
    if (rows_hit < need) continue;
    f.selected = c;
    f.found = true;
    if (!f.placed_arc.full() && f.placed_arc.span_rad < options_.weak_arc_rad) {
      // A free ellipse through a short arc swings about it (five parameters, little curvature
      // seen); keep the shape the lines were placed on and fit only its shift, from the inliers'
      // offsets along their lines' normals (damped: the shift along a short arc's chord is weakly
      // seen).
      Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
      Eigen::Vector2d b = Eigen::Vector2d::Zero();
      for (int q = 0; q < cand.support; ++q) {
        const Edgel& e = f.result.edgels.edgels[static_cast<std::size_t>(f.candidate_inliers[static_cast<std::size_t>(cand.inlier_begin + q)])];
        const Eigen::Vector2d& n = f.lines[static_cast<std::size_t>(e.row)].normal;
        A.noalias() += n * n.transpose();
        b += static_cast<double>(e.x_px) * n;
      }
      A.diagonal().array() += 1e-2 * A.trace() + 1e-9;
      Ellipse shifted = f.placed_on;
      shifted.centre_px += A.ldlt().solve(b);
      f.candidates[static_cast<std::size_t>(c)].ellipse = shifted;
    }
    f.ellipse = f.candidates[static_cast<std::size_t>(c)].ellipse;
    return;
  }
  std::fill(f.row_hit.begin(), f.row_hit.end(), 0);
}

void EllipseTracker::update_arc(EllipseFeature& f, const Eigen::Matrix3d* circle_to_px) {
  f.has_circle_arc = false;
  const int reached_begin = f.extension_begin, reached_end = f.extension_end;
  f.extension_begin = f.extension_end = 1;
  if (!f.found) {
    f.has_previous = false;  // lost: the next frame starts again from the projection, all round
    f.arc = {};
    return;
  }
  f.has_previous = true;
  const int rows = static_cast<int>(f.lines.size());
  const Eigen::Vector2d c = f.ellipse.centre_px;
  auto polar = [&](int r) { return polar_about(c, f.lines[static_cast<std::size_t>(r)].centre_px); };
  // Angle swept from row a to row b going through the rows in order (cyclically for a full ellipse).
  auto sweep = [&](int a, int b) {
    double span = 0;
    for (int r = a; r != b; r = (r + 1) % rows) span += std::fabs(wrap_angle(polar((r + 1) % rows) - polar(r)));
    return span;
  };
  // The arc from row `first` to row `last`: polar about the fit, and in the circle's own angle
  // when its image map was given.
  auto set_arc = [&](int first, int last) {
    f.arc.begin_rad = polar(first);
    f.arc.span_rad = sweep(first, last);
    if (!circle_to_px) return;
    f.circle_arc = circle_arc_between(*circle_to_px, f.lines[static_cast<std::size_t>(first)].centre_px,
                                      f.lines[static_cast<std::size_t>(last)].centre_px);
    f.has_circle_arc = true;
  };
  const int gap = std::max(options_.min_gap_lines, 1);
  const double line_step_rad = kTwoPi / options_.lines;
  if (f.placed_arc.full()) {
    // The longest cyclic run of lines without an inlier.
    int best_len = 0, best_start = -1;
    for (int s = 0; s < rows; ++s) {
      if (f.row_hit[static_cast<std::size_t>(s)] || !f.row_hit[static_cast<std::size_t>((s + rows - 1) % rows)]) continue;
      int len = 0;
      while (len < rows && !f.row_hit[static_cast<std::size_t>((s + len) % rows)]) ++len;
      if (len > best_len) { best_len = len; best_start = s; }
    }
    if (best_len < gap || best_start < 0) { f.arc = {}; f.weak = false; return; }
    set_arc((best_start + best_len) % rows, (best_start + rows - 1) % rows);
    ++f.occlusions;
  } else {
    // Rows run extension, arc lines, extension. The arc runs from the first to the last line
    // with an inlier: its ends shrink onto an advancing occluder and grow onto the extension
    // lines when it recedes. A gap inside the arc (a second occluder) stays inside it, its
    // lines simply finding no inliers, so both sides of it keep constraining the fit.
    int first = -1, last = -1;
    for (int r = 0; r < rows; ++r)
      if (f.row_hit[static_cast<std::size_t>(r)]) {
        if (first < 0) first = r;
        last = r;
      }
    if (first < 0 || last <= first) { f.arc = {}; return; }
    set_arc(first, last);
    if (kTwoPi - f.arc.span_rad < 1.5 * line_step_rad) {  // the ends have met: the occluder has left
      f.arc = {};
      f.has_circle_arc = false;
      ++f.recoveries;
    } else {
      // An extension line that found the rim reaches twice as far next frame, but the two never
      // beyond the middle of the gap left (the next spacing is about span / (lines - 1)).
      const double gap_spacings = (kTwoPi - f.arc.span_rad) / f.arc.span_rad * (options_.lines - 1);
      const int cap = std::clamp(static_cast<int>(0.5 * gap_spacings), 1, std::max(options_.max_extension_spacings, 1));
      if (first == 0) f.extension_begin = std::min(2 * reached_begin, cap);
      if (last == rows - 1) f.extension_end = std::min(2 * reached_end, cap);
    }
  }
  f.weak = !f.arc.full() && f.arc.span_rad < options_.weak_arc_rad;
}

bool EllipseTracker::observation(const EllipseFeature& f, const ModelCircle& circle, EllipseObservation& out) const {
  if (!f.found || f.selected < 0) return false;
  const EllipseFit& c = f.candidates[static_cast<std::size_t>(f.selected)];
  out.feature = f.circle;
  out.circle = circle;
  out.points_px.clear();
  for (int q = 0; q < c.support; ++q)
    out.points_px.push_back(edgel_px(f, f.candidate_inliers[static_cast<std::size_t>(c.inlier_begin + q)]));
  out.sigma_px = options_.sigma_px * (f.weak ? options_.weak_sigma_factor : 1.0);
  return true;
}

}  // namespace epichead::vision
