#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/object_region.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>

namespace epichead::vision {

const char* to_string(EllipseRefusal refusal) {
  switch (refusal) {
    case EllipseRefusal::None: return "none";
    case EllipseRefusal::NoCandidate: return "no_candidate";
    case EllipseRefusal::LeavesWindow: return "leaves_window";
    case EllipseRefusal::OtherShape: return "other_shape";
    case EllipseRefusal::FewLines: return "few_lines";
  }
  return "?";
}

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
    f.refused = EllipseRefusal::None;
    f.selected = -1;
    f.arc = {};
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
  for (EllipseFeature& f : features_) {
    f.visible = f.found = f.weak = false;
    f.refused = EllipseRefusal::None;
  }
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
    track_one(image, v.circle, projection, placement, v.side, v.seen);
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
    f.lines[0] = tracker_line_beyond(on, arc.begin_rad, step, -1);
    f.lines[static_cast<std::size_t>(n) + 1] = tracker_line_beyond(on, arc.begin_rad + arc.span_rad, step, +1);
    f.arc_row_begin = 1;
    f.arc_row_end = n + 1;
  }
  if (!(step > 0)) { f.lines.clear(); return false; }
  return window_.sample(image, f.lines.data(), static_cast<int>(f.lines.size()));
}

void EllipseTracker::track_one(const WindowImage& image, int circle, const Ellipse& projection, WindowPlacement placement,
                               ObjectSide model_side, const EllipseArc& seen) {
  if (circle < 0) return;
  EllipseFeature& f = feature(circle);
  f.visible = f.found = f.weak = false;
  f.refused = EllipseRefusal::None;
  f.selected = -1;
  f.candidates.clear();
  f.candidate_inliers.clear();
  f.row_hit.clear();
  f.side = options_.side == RimSide::Model ? model_side : object_side(options_.side);
  if (!projection.valid()) { f.has_previous = false; return; }
  if (!f.refs.initialised && options_.mode != EpicMode::Gradient) {
    // References from both sides of the seen projected contour, whatever the placement.
    if (place(image, f, projection, seen)) detector_.init_references(window_.window(), f.side, f.refs);
  }
  Ellipse on = projection;
  EllipseArc arc = seen;
  if (placement == WindowPlacement::Previous && f.has_previous) {
    on = f.ellipse;
    arc = f.arc;
  } else if (placement == WindowPlacement::ProjectionOnArc && f.has_previous) {
    arc = f.arc;  // polar angles about the centre: they carry over to the projection
  }
  // Never onto the part the model hides (an arc found last frame may have grown into it).
  if (const auto both = EllipseArc::overlap(arc, seen)) arc = *both;
  else arc = seen;
  if (!place(image, f, on, arc)) {
    f.has_previous = false;
    f.arc = {};
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
  update_arc(f);
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

bool EllipseTracker::placed_shape(const EllipseFeature& f, const Ellipse& e) const {
  // The prediction fixes a circle's image to a few percent in size (its distance) and a few
  // degrees in openness (semi-minor / semi-major, the cosine of the angle between the line of
  // sight and the circle's axis). A candidate much larger, smaller, flatter or rounder is
  // another contour: a band printed round a can just below its top rim, joined with the rim's
  // own far arc, fits an ellipse 15-25 % larger and twice as open.
  const Ellipse& p = f.placed_on;
  return !p.valid() || !e.valid() ||
         (std::abs(e.semi_major_px / p.semi_major_px - 1) <= options_.max_size_change &&
          std::abs(e.semi_minor_px / e.semi_major_px - p.semi_minor_px / p.semi_major_px) <= options_.max_openness_change);
}

bool EllipseTracker::plausible(const EllipseFeature& f, const Ellipse& e) const {
  // The new contour must cross every arc line inside its window: an ellipse fitted to a short
  // arc can otherwise swing far from where any line looked (it has no support there). The
  // Sampson distance overstates the distance near a flat ellipse's major axis, which refuses a
  // flat rim's candidates moved across it by more than about its semi-minor axis; the exact
  // distance was tried and lost runs to printed bands beside the rims (docs/epic.md).
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

bool EllipseTracker::moved_placement(EllipseFeature& f, EllipseFit& out) const {
  // Edgel k lies x_k along its line's normal n_k from the placed contour. Moving the placed
  // ellipse by s and scaling it by (1 + k) about its centre c moves the contour at line point p
  // by n.s + k (p - c).n along n. Hypotheses: the shift through two edgels of lines at least
  // 30 deg apart; then shift and scale refitted to the best one's inliers.
  const std::vector<int>& good = f.result.good;
  const int n = static_cast<int>(good.size());
  if (n < 5) return false;
  const double tol = options_.ransac.inlier_distance_px;
  const Eigen::Vector2d c = f.placed_on.centre_px;
  auto edgel = [&](int i) -> const Edgel& { return f.result.edgels.edgels[static_cast<std::size_t>(good[static_cast<std::size_t>(i)])]; };
  auto line = [&](int i) -> const TrackerLine& { return f.lines[static_cast<std::size_t>(edgel(i).row)]; };
  // What the placed contour moved by `shift` and scaled by 1 + `scale` leaves of edgel i's offset.
  auto residual = [&](int i, const Eigen::Vector2d& shift, double scale) {
    const TrackerLine& l = line(i);
    return static_cast<double>(edgel(i).x_px) - l.normal.dot(shift) - scale * (l.centre_px - c).dot(l.normal);
  };
  auto count = [&](const Eigen::Vector2d& shift) {
    int inliers = 0;
    for (int i = 0; i < n; ++i) inliers += std::abs(residual(i, shift, 0)) <= tol;
    return inliers;
  };
  // Deterministic pairs spread over the edgels: at most kPairs of them.
  constexpr int kPairs = 96;
  const int stride = std::max(1, n * (n - 1) / 2 / kPairs);
  Eigen::Vector2d best_shift = Eigen::Vector2d::Zero();
  int best = -1, pair = 0;
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j, ++pair) {
      if (pair % stride != 0) continue;
      const Eigen::Vector2d& ni = line(i).normal;
      const Eigen::Vector2d& nj = line(j).normal;
      const double det = ni.x() * nj.y() - ni.y() * nj.x();
      if (std::abs(det) < 0.5) continue;  // lines closer than 30 deg: the shift along them is unseen
      const double xi = edgel(i).x_px, xj = edgel(j).x_px;
      const Eigen::Vector2d shift((xi * nj.y() - xj * ni.y()) / det, (ni.x() * xj - nj.x() * xi) / det);
      const int support = count(shift);
      if (support > best) { best = support; best_shift = shift; }
    }
  if (best < 5) return false;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) {
    if (std::abs(residual(i, best_shift, 0)) > tol) continue;
    const TrackerLine& l = line(i);
    const Eigen::Vector3d j(l.normal.x(), l.normal.y(), (l.centre_px - c).dot(l.normal));
    A.noalias() += j * j.transpose();
    b += static_cast<double>(edgel(i).x_px) * j;
  }
  A.diagonal().array() += 1e-6 * A.trace() + 1e-9;
  const Eigen::Vector3d fit = A.ldlt().solve(b);
  const Eigen::Vector2d shift = fit.head<2>();
  const double scale = std::abs(fit.z()) <= options_.max_size_change ? fit.z() : 0.0;
  out = EllipseFit{};
  out.ellipse = f.placed_on;
  out.ellipse.centre_px += shift;
  out.ellipse.semi_major_px *= 1 + scale;
  out.ellipse.semi_minor_px *= 1 + scale;
  out.inlier_begin = static_cast<int>(f.candidate_inliers.size());
  for (int i = 0; i < n; ++i) {
    if (std::abs(residual(i, shift, scale)) > tol) continue;
    f.candidate_inliers.push_back(good[static_cast<std::size_t>(i)]);
    ++out.support;
  }
  return out.support >= 5;
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
  // Between frames an axis changes by less than half a tracker line, or the lines miss it anyway.
  EllipseRansacOptions& ro = ransac_.options();
  const double half = 0.5 * window_.width_px();
  ro.max_candidates = options_.mode == EpicMode::Epic ? options_.ransac.max_candidates : 1;
  ro.max_semi_major_px = std::min(options_.ransac.max_semi_major_px, f.placed_on.semi_major_px + half);
  ro.min_semi_minor_px = std::max(options_.ransac.min_semi_minor_px, f.placed_on.semi_minor_px - half);
  ransac_.fit(px_x_.data(), px_y_.data(), px_row_.data(), n);
  f.ransac_iterations = ransac_.iterations();
  for (const EllipseFit& fit : ransac_.candidates()) {
    EllipseFit c = fit;
    c.inlier_begin = static_cast<int>(f.candidate_inliers.size());
    for (int q = 0; q < fit.support; ++q)
      f.candidate_inliers.push_back(f.result.good[static_cast<std::size_t>(ransac_.inliers()[static_cast<std::size_t>(fit.inlier_begin + q)])]);
    f.candidates.push_back(c);
  }
  // Select the best-supported plausible candidate of the placed shape with inliers on enough
  // tracker lines (topology validation may later choose among the candidates instead). When
  // free fits were refused only for their shape, they are other contours: last in line comes
  // the placed ellipse moved onto the edgels it explains (a rim half under a board or a lamp's
  // arm, whose best free fit runs along the occluder's edge).
  const int arc_lines = f.arc_row_end - f.arc_row_begin;
  const int need = std::max(std::max(options_.ransac.min_support, 5),
                            static_cast<int>(std::ceil(options_.min_support_ratio * static_cast<float>(arc_lines))));
  f.row_hit.assign(f.lines.size(), 0);
  bool other_shape = false, moved_tried = false;
  // The first refused candidate is the best supported: its reason is the feature's.
  f.refused = EllipseRefusal::NoCandidate;
  const auto refuse = [&f](EllipseRefusal why) {
    if (f.refused == EllipseRefusal::NoCandidate) f.refused = why;
  };
  for (int c = 0;; ++c) {
    if (c == static_cast<int>(f.candidates.size())) {
      if (!other_shape || moved_tried || options_.mode != EpicMode::Epic || !f.placed_arc.full()) break;
      moved_tried = true;
      EllipseFit moved;
      if (!moved_placement(f, moved)) break;
      f.candidates.push_back(moved);  // within the reserved capacity
    }
    const EllipseFit& cand = f.candidates[static_cast<std::size_t>(c)];
    if (!plausible(f, cand.ellipse)) {
      refuse(EllipseRefusal::LeavesWindow);
      continue;
    }
    if (!placed_shape(f, cand.ellipse)) {
      refuse(EllipseRefusal::OtherShape);
      other_shape = true;
      continue;
    }
    std::fill(f.row_hit.begin(), f.row_hit.end(), 0);
    for (int q = 0; q < cand.support; ++q)
      f.row_hit[static_cast<std::size_t>(f.result.edgels.edgels[static_cast<std::size_t>(f.candidate_inliers[static_cast<std::size_t>(cand.inlier_begin + q)])].row)] = 1;
    int rows_hit = 0;
    for (unsigned char h : f.row_hit) rows_hit += h;
    if (rows_hit < need) {
      refuse(EllipseRefusal::FewLines);
      continue;
    }
    f.selected = c;
    f.found = true;
    f.refused = EllipseRefusal::None;
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

void EllipseTracker::update_arc(EllipseFeature& f) {
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
    const int first = (best_start + best_len) % rows, last = (best_start + rows - 1) % rows;
    f.arc.begin_rad = polar(first);
    f.arc.span_rad = sweep(first, last);
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
    f.arc.begin_rad = polar(first);
    f.arc.span_rad = sweep(first, last);
    if (kTwoPi - f.arc.span_rad < 1.5 * line_step_rad) {  // the ends have met: the occluder has left
      f.arc = {};
      ++f.recoveries;
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
