#include "epichead/vision/model_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace epichead::vision {
namespace {

void count_refusal(EllipseRefusal refusal, EllipseRefusals& counts) {
  switch (refusal) {
    case EllipseRefusal::None: break;
    case EllipseRefusal::NoCandidate: ++counts.no_candidate; break;
    case EllipseRefusal::LeavesWindow: ++counts.leaves_window; break;
    case EllipseRefusal::OtherShape: ++counts.other_shape; break;
    case EllipseRefusal::FewLines: ++counts.few_lines; break;
  }
}

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

EpicMode epic_mode(TrackMode mode) {
  switch (mode) {
    case TrackMode::Gradient: return EpicMode::Gradient;
    case TrackMode::Epic: return EpicMode::EpicSingle;
    case TrackMode::EpicValidation: return EpicMode::Epic;
  }
  return EpicMode::Epic;
}

EllipseTrackerOptions ellipse_options(const ModelTrackerOptions& o) {
  EllipseTrackerOptions e = o.ellipses;
  e.mode = epic_mode(o.mode);
  return e;
}

LineTrackerOptions line_options(const ModelTrackerOptions& o) {
  LineTrackerOptions l = o.lines;
  l.mode = epic_mode(o.mode);
  return l;
}

// Line-feature states kept across frames, for counting recoveries.
enum : unsigned char { kNotVisible = 0, kMissed = 1, kKept = 2 };

}  // namespace

const char* to_string(TrackMode mode) {
  switch (mode) {
    case TrackMode::Gradient: return "gradient";
    case TrackMode::Epic: return "epic";
    case TrackMode::EpicValidation: return "epic+validation";
  }
  return "unknown";
}

const char* to_string(TrackStatus status) {
  switch (status) {
    case TrackStatus::Tracked: return "tracked";
    case TrackStatus::Degraded: return "degraded";
    case TrackStatus::Lost: return "lost";
  }
  return "unknown";
}

bool strongly_supported(const FrameReport& r) {
  const int found = r.found + 2 * r.ellipses_found, kept = r.inliers + 2 * r.ellipses_found;
  return r.status == TrackStatus::Tracked && kept >= 6 && kept >= 0.8 * found;
}

std::string to_string(TrackReason reasons) {
  static constexpr std::pair<TrackReason, const char*> names[] = {
      {TrackReason::NotVisible, "not_visible"}, {TrackReason::FewFeatures, "few_features"},
      {TrackReason::PoseFailed, "pose_failed"}, {TrackReason::FewInliers, "few_inliers"},
      {TrackReason::HighResidual, "high_residual"}, {TrackReason::Jump, "jump"},
      {TrackReason::Reacquired, "reacquired"},
      {TrackReason::AgainstGravity, "against_gravity"},
      {TrackReason::AgainstImageMotion, "against_image_motion"},
      {TrackReason::AgainstCarriedTurn, "against_carried_turn"}};
  std::string s;
  for (const auto& [bit, name] : names) {
    if (!has(reasons, bit)) continue;
    if (!s.empty()) s += '+';
    s += name;
  }
  return s;
}

ModelTracker::ModelTracker(const CadModel& model, const Camera& camera, const ModelTrackerOptions& options)
    : model_(&model),
      camera_(camera),
      options_(options),
      visibility_(model, camera, options.visibility),
      rim_sides_(model, camera),
      lines_(line_options(options)),
      ellipses_(ellipse_options(options)),
      validator_(model, options.validation),
      estimator_(camera, options.pose),
      region_(options.outline) {
  const std::size_t edges = model.edges.size();
  // One pose-problem slot per model edge, kept for the tracker's life: a slot's edgel buffer
  // keeps its capacity, and unused slots (no edgels) are ignored by the estimator. A slot's
  // segment is set each frame from the piece seen (build_problem).
  problem_.lines.resize(edges);
  for (std::size_t e = 0; e < edges; ++e) {
    LineObservation& obs = problem_.lines[e];
    obs.feature = static_cast<int>(e);
    obs.edgels_px.reserve(static_cast<std::size_t>(options.lines.window.max_rows) * 4);
  }
  problem_.points.reserve(model.vertices.size());
  if (options.free_turn_of_revolution) problem_.free_turn = find_revolution_axis(model);
  // A smooth body's facets are the model's error at every edge (its contour and its rims).
  if (problem_.free_turn)
    for (LineObservation& obs : problem_.lines) obs.model_error_m = problem_.free_turn->facet_sagitta_m;
  // Model edges that are chords of a model circle (both ends on it): the facets' outline of a
  // rim the circle itself describes.
  chord_of_circle_.assign(edges, -1);
  for (std::size_t e = 0; e < edges; ++e) {
    const Eigen::Vector3d& a = model.vertices[static_cast<std::size_t>(model.edges[e].v0)];
    const Eigen::Vector3d& b = model.vertices[static_cast<std::size_t>(model.edges[e].v1)];
    for (std::size_t c = 0; c < model.circles.size() && chord_of_circle_[e] < 0; ++c)
      if (on_circle(model.circles[c], a) && on_circle(model.circles[c], b)) chord_of_circle_[e] = static_cast<int>(c);
  }
  // One slot per model circle, like the lines (a slot without points is ignored).
  problem_.ellipses.resize(model.circles.size());
  for (std::size_t c = 0; c < model.circles.size(); ++c) {
    problem_.ellipses[c].feature = static_cast<int>(c);
    problem_.ellipses[c].circle = model.circles[c];
    problem_.ellipses[c].points_px.reserve(static_cast<std::size_t>(options.ellipses.lines) * 4);
  }
  kept_last_.assign(edges, kNotVisible);
  kept_now_.assign(edges, kNotVisible);
  // The estimator's and the result's per-feature buffers at the model's full size.
  std::size_t observations = 0;
  for (const LineObservation& obs : problem_.lines) observations += obs.edgels_px.capacity();
  for (const EllipseObservation& obs : problem_.ellipses) observations += obs.points_px.capacity();
  const std::size_t slots = edges + model.vertices.size() + model.circles.size();
  estimator_.reserve(slots, observations);
  pose_.residuals.reserve(slots);
  // The first frame is a start: its windows and its outline colours must not wait on the
  // allocator or on page faults.
  lines_.reserve(static_cast<int>(edges));
  if (options.outline_colours) region_.reserve(camera.width_px(), camera.height_px());
}

void ModelTracker::reset() {
  lines_.reset();
  ellipses_.reset();
  settled_ = false;
  std::fill(kept_last_.begin(), kept_last_.end(), kNotVisible);
  was_lost_ = false;
}

void ModelTracker::build_problem() {
  const auto& features = lines_.features();
  const bool validated = options_.mode == TrackMode::EpicValidation;
  for (std::size_t e = 0; e < problem_.lines.size(); ++e) {
    LineObservation& obs = problem_.lines[e];
    obs.edgels_px.clear();
    if (e >= features.size()) continue;
    const LineFeature& f = features[e];
    const int chosen = validated ? validation_.selected[e] : f.selected;
    if (!f.visible || chosen < 0) continue;
    // The piece seen, not the whole model edge: the same 3D line (so the same residuals), but
    // the pose's "in front of the camera" test is then about what is seen. A room's wall edge
    // runs behind the camera; with its far vertex behind, no step would ever pass that test
    // and the pose stayed at the prediction (office_pan: the 1 cm / 1 deg start error for good).
    obs.a_obj = f.piece.a_obj;
    obs.b_obj = f.piece.b_obj;
    const LineCandidate& c = f.result.candidates[static_cast<std::size_t>(chosen)];
    const WindowGeometry& g = f.result.geometry;
    const int n = std::min(c.support, std::max(2, options_.max_edgels_per_line));
    for (int i = 0; i < n; ++i) {
      const int k = n > 1 ? static_cast<int>((static_cast<long>(i) * (c.support - 1)) / (n - 1)) : 0;
      const Edgel& edgel = f.result.edgels.edgels[static_cast<std::size_t>(f.result.inliers[static_cast<std::size_t>(c.inlier_begin + k)])];
      obs.edgels_px.push_back(g.to_image(edgel.x_px, edgel.s_px));
    }
  }
  problem_.points.clear();
  if (validated && options_.use_junctions) {
    for (const ValidatedJunction& j : validation_.junctions) {
      PointObservation p;
      p.feature = j.vertex;
      p.p_obj = model_->vertices[static_cast<std::size_t>(j.vertex)];
      p.px = j.px;
      // A junction from more intersections is better located; sigma about one edgel's.
      p.sigma_px = 1.5 / std::sqrt(static_cast<double>(j.lines));
      problem_.points.push_back(p);
    }
  }
}

bool ModelTracker::measure(const WindowImage& image, const Eigen::Isometry3d& predicted, FrameReport& out) {
  auto t = Clock::now();
  visibility_.compute(predicted, visible_);
  rim_sides_.apply(predicted, visible_);
  if (options_.circles_replace_chords && !visible_.ellipses.empty()) {
    // A rim seen as an ellipse is tracked as one: its chords would count it a second time,
    // thirty-odd short windows that a printed band along the rim pulls off together.
    std::erase_if(visible_.edges, [&](const VisibleEdge& e) {
      const int c = static_cast<std::size_t>(e.edge) < chord_of_circle_.size() ? chord_of_circle_[static_cast<std::size_t>(e.edge)] : -1;
      if (c < 0 || e.kind == EdgeKind::CylinderSilhouette) return false;
      for (const VisibleEllipse& v : visible_.ellipses)
        if (v.circle == c) return true;
      return false;
    });
  }
  out.times.visibility_ms += ms_since(t);

  t = Clock::now();
  lines_.detect(image, visible_, WindowPlacement::Projection);
  out.times.epic_ms += ms_since(t);
  const auto& features = lines_.features();
  out.visible = out.found = 0;
  for (const LineFeature& f : features) {
    out.visible += f.visible;
    out.found += f.visible && f.selected >= 0;
  }
  out.ellipses_visible = out.ellipses_found = out.ellipses_weak = 0;
  out.ellipses_refused = {};
  for (EllipseObservation& obs : problem_.ellipses) obs.points_px.clear();
  if (!visible_.ellipses.empty()) {
    t = Clock::now();
    ellipses_.track(image, visible_, WindowPlacement::ProjectionOnArc);
    for (const EllipseFeature& f : ellipses_.features()) {
      out.ellipses_visible += f.visible;
      if (f.visible) count_refusal(f.refused, out.ellipses_refused);
      if (!f.visible || !f.found || f.circle < 0 || f.circle >= static_cast<int>(problem_.ellipses.size())) continue;
      EllipseObservation& obs = problem_.ellipses[static_cast<std::size_t>(f.circle)];
      if (ellipses_.observation(f, model_->circles[static_cast<std::size_t>(f.circle)], obs)) {
        ++out.ellipses_found;
        out.ellipses_weak += f.weak;
      }
    }
    out.times.epic_ms += ms_since(t);
  }

  t = Clock::now();
  if (options_.mode == TrackMode::EpicValidation) {
    validator_.validate(image, features, validation_);
    out.validated_changed = validation_.changed;
    out.combinations += validation_.combinations;
  }
  out.times.validation_ms += ms_since(t);

  t = Clock::now();
  build_problem();
  out.junctions = static_cast<int>(problem_.points.size());
  std::fill(kept_now_.begin(), kept_now_.end(), kNotVisible);
  for (const LineFeature& f : features)
    if (f.visible && static_cast<std::size_t>(f.edge) < kept_now_.size()) kept_now_[static_cast<std::size_t>(f.edge)] = kMissed;

  TrackReason reasons = TrackReason::None;
  if (out.visible + out.ellipses_visible < 2) reasons = reasons | TrackReason::NotVisible;
  if (out.found + 2 * out.ellipses_found < options_.min_features) reasons = reasons | TrackReason::FewFeatures;
  bool pose_ok = reasons == TrackReason::None;
  out.inliers = out.rejected = 0;
  if (pose_ok) {
    estimator_.estimate(problem_, predicted, pose_);
    out.pose_status = pose_.status;
    out.pose_iterations += pose_.iterations;
    if (pose_.status != PoseStatus::Ok) {
      reasons = reasons | TrackReason::PoseFailed;
      pose_ok = false;
    }
  }
  if (pose_ok) {
    // Plausibility: how far the visible model moved in the image from the prediction.
    double moved = 0;
    int n = 0;
    for (const VisibleEdge& e : visible_.edges) {
      for (const Eigen::Vector3d* p : {&e.a_obj, &e.b_obj}) {
        const Eigen::Vector3d q = pose_.cam_T_obj * *p;
        if (!(q.z() > 0)) { moved = 1e9; continue; }
        moved += (camera_.project(q) - camera_.project(predicted * *p)).norm();
        ++n;
      }
    }
    if (n > 0 && moved / n > options_.max_jump_px) {
      reasons = reasons | TrackReason::Jump;
      pose_ok = false;
    }
  }
  if (pose_ok) {
    for (const FeatureResidual& r : pose_.residuals) {
      // Line slots carry the model edge as feature id; points follow them.
      if (&r - pose_.residuals.data() >= static_cast<std::ptrdiff_t>(problem_.lines.size())) break;
      if (problem_.lines[static_cast<std::size_t>(r.feature)].edgels_px.size() < 2) continue;
      if (r.inlier) { ++out.inliers; kept_now_[static_cast<std::size_t>(r.feature)] = kKept; }
      else ++out.rejected;
    }
    out.cam_T_obj = pose_.cam_T_obj;
    out.covariance = pose_.covariance;
    out.scale_px = pose_.scale_px;
    int ellipse_inliers = 0;
    const std::size_t first_ellipse = problem_.lines.size() + problem_.points.size();
    for (std::size_t k = first_ellipse; k < first_ellipse + problem_.ellipses.size() && k < pose_.residuals.size(); ++k)
      ellipse_inliers += problem_.ellipses[k - first_ellipse].points_px.size() >= 5 && pose_.residuals[k].inlier;
    if (out.inliers + 2 * ellipse_inliers < 3) {
      reasons = reasons | TrackReason::FewInliers;
      pose_ok = false;
    } else if (out.inliers + 2 * ellipse_inliers < options_.min_inlier_ratio * (out.found + 2 * out.ellipses_found)) {
      reasons = reasons | TrackReason::FewInliers;
    }
    if (pose_ok && pose_.scale_px > options_.max_scale_px) {
      reasons = reasons | TrackReason::HighResidual;
      if (pose_.scale_px > 2 * options_.max_scale_px) pose_ok = false;
    }
  }
  out.times.pose_ms += ms_since(t);
  out.reasons = reasons;
  return pose_ok;
}

void ModelTracker::set_mode(TrackMode mode) {
  options_.mode = mode;
  lines_.set_mode(epic_mode(mode));
  ellipses_.set_mode(epic_mode(mode));
}

Eigen::Isometry3d ModelTracker::settle(const WindowImage& image, const Eigen::Isometry3d& predicted, StageTimes& times,
                                       FrameReport& measured, bool& reused, StartSettle& record) {
  reused = false;
  record = StartSettle{};
  // How well the image supports a measurement: the share of found features the pose keeps.
  const auto support = [](const FrameReport& r) {
    return static_cast<double>(r.inliers + 2 * r.ellipses_found) / std::max(1, r.found + 2 * r.ellipses_found);
  };
  const TrackMode mode = options_.mode;
  if (mode == TrackMode::Gradient) return predicted;  // gradient needs no references
  FrameReport direct, gradient, refined;
  const bool direct_ok = measure(image, predicted, direct);
  set_mode(TrackMode::Gradient);
  const bool gradient_ok = measure(image, predicted, gradient);
  set_mode(mode);
  times.add_stages(direct.times);
  times.add_stages(gradient.times);
  record.settled = true;
  if (direct_ok) record.support_given = support(direct);
  if (!gradient_ok) return predicted;
  // References afresh from the gradient pose's projection.
  lines_.reset();
  ellipses_.reset();
  const bool refined_ok = measure(image, gradient.cam_T_obj, refined);
  times.add_stages(refined.times);
  if (refined_ok) record.support_gradient = support(refined);
  if (refined_ok && (!direct_ok || support(refined) >= support(direct))) {
    record.kept_gradient = true;
    // The tracker's state (features, validation, pose) is still that of the refined measurement,
    // and a line's measurement depends only on the image, the pose and its references. Not so
    // an ellipse's: its tracker lines are placed on the arc its last measurement found.
    if (refined.ellipses_visible > 0) return gradient.cam_T_obj;
    measured = refined;
    measured.times = StageTimes{};  // already in `times`
    reused = true;
    return gradient.cam_T_obj;
  }
  lines_.reset();
  ellipses_.reset();
  return predicted;
}

void ModelTracker::track(const WindowImage& image, const Eigen::Isometry3d& predicted, FrameReport& out) {
  track(image, predicted, nullptr, out);
}

void ModelTracker::track(const WindowImage& image, const Eigen::Isometry3d& predicted, const Eigen::Isometry3d* fallback,
                         FrameReport& out) {
  const auto t_start = Clock::now();
  out = FrameReport{};
  out.cam_T_obj = predicted;
  StageTimes settling;
  // Only from a start (construction or reset: init.csv, a detection), which is near the
  // object: after a loss the prediction may be far enough off to draw the background into the
  // object's histogram (a mockup_walk step burst: re-locked 5 deg off with them).
  if (!settled_ && !was_lost_ && options_.outline_colours && options_.mode != TrackMode::Gradient) {
    const auto t = Clock::now();
    if (region_.learn(image, *model_, camera_, predicted)) {
      lines_.set_outline(&region_);
      ellipses_.set_outline(&region_);
    }
    settling.epic_ms += ms_since(t);
  }
  bool reused = false;
  StartSettle start_record;
  const Eigen::Isometry3d start =
      settled_ || !options_.settle ? predicted : settle(image, predicted, settling, out, reused, start_record);
  bool pose_ok = reused || measure(image, start, out);
  out.times.add_stages(settling);
  if (!pose_ok && fallback) {
    // The second opinion: measured afresh from the other prediction (measure() learns nothing,
    // so the first attempt leaves no trace but its stage times, which add up).
    lines_.set_outline(nullptr);  // the region was drawn at the other prediction
    ellipses_.set_outline(nullptr);
    const StageTimes first = out.times;
    const int iterations = out.pose_iterations;
    out = FrameReport{};
    out.cam_T_obj = *fallback;
    out.times = first;
    out.pose_iterations = iterations;
    pose_ok = measure(image, *fallback, out);
    out.used_fallback = true;
    if (!pose_ok) out.cam_T_obj = predicted;
  }
  lines_.set_outline(nullptr);
  ellipses_.set_outline(nullptr);
  const auto& features = lines_.features();
  TrackReason reasons = out.reasons;
  if (!pose_ok) {
    out.status = TrackStatus::Lost;
    out.cam_T_obj = predicted;
    out.used_fallback = false;
    for (const LineFeature& f : features)
      if (f.visible) lines_.reject(f.edge);
    std::fill(kept_now_.begin(), kept_now_.end(), kNotVisible);
  } else {
    out.status = reasons == TrackReason::None ? TrackStatus::Tracked : TrackStatus::Degraded;
    if (was_lost_) reasons = reasons | TrackReason::Reacquired;
    // Only lines the pose explains teach their cue references; the rest start over from the
    // projection next frame (recovery).
    const bool validated = options_.mode == TrackMode::EpicValidation;
    for (const LineFeature& f : features) {
      if (!f.visible) continue;
      const std::size_t e = static_cast<std::size_t>(f.edge);
      if (kept_now_[e] == kKept) {
        lines_.accept(f.edge, validated ? validation_.selected[e] : f.selected);
        out.recovered += kept_last_[e] == kMissed;
      } else {
        lines_.reject(f.edge);
      }
    }
  }
  out.reasons = reasons;
  out.start = start_record;
  was_lost_ = out.status == TrackStatus::Lost;
  settled_ = !was_lost_;
  std::swap(kept_last_, kept_now_);
  out.times.total_ms = ms_since(t_start);
}

}  // namespace epichead::vision
