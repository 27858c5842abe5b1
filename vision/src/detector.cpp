#include "epichead/vision/detector.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "detector_impl.h"
#include "epichead/geometry/so3.h"
#include "hypothesis_places.h"
#include "view_sphere.h"

namespace epichead::vision {

using detail::Clock;
using detail::ms_since;

namespace {

// The query image is padded to a multiple of 16 so that LINE-2D's two pyramid levels divide
// into its T-sized cells.
constexpr int kPadMultiple = 16;

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
}

// Mean distance from each point of one set to the nearest of the other, both ways (a symmetric
// chamfer distance): small when two poses draw the same outline, whichever points match.
double outline_distance_px(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  auto one_way = [](const std::vector<Eigen::Vector2d>& p, const std::vector<Eigen::Vector2d>& q) {
    double sum = 0;
    for (const auto& x : p) {
      double best = 1e300;
      for (const auto& y : q) best = std::min(best, (x - y).squaredNorm());
      sum += std::sqrt(best);
    }
    return p.empty() ? 1e300 : sum / static_cast<double>(p.size());
  };
  return 0.5 * (one_way(a, b) + one_way(b, a));
}

}  // namespace

std::vector<std::string> Detector::Impl::classes_for(const DetectionPrior& prior) const {
  std::vector<std::string> ids;
  // Off the optical axis the pose turns by up to half the field of view; the view's own
  // up tolerance comes on top of it (hypotheses are checked again after that turn).
  const double half_fov_deg =
      std::atan(0.5 * std::hypot(camera.width_px(), camera.height_px()) / camera.intrinsics().fx_px) * 180.0 / M_PI;
  for (const auto& [id, list] : class_specs) {
    if (list.empty()) continue;
    if (prior.up_cam && prior.up_obj) {
      const auto& s = specs[static_cast<std::size_t>(list.front())];
      const Eigen::Matrix3d R = detail::look_rotation(views[static_cast<std::size_t>(s.view)], rolls_rad[static_cast<std::size_t>(s.roll)]);
      if (angle_deg(R * *prior.up_obj, *prior.up_cam) > options.up_tolerance_deg + half_fov_deg) continue;
    }
    if (prior.cam_R_obj) {
      const auto& s = specs[static_cast<std::size_t>(list.front())];
      const Eigen::Matrix3d R = detail::look_rotation(views[static_cast<std::size_t>(s.view)], rolls_rad[static_cast<std::size_t>(s.roll)]);
      if (!turned_near(R, prior, template_turn_slack_deg() + half_fov_deg)) continue;
    }
    ids.push_back(id);
  }
  return ids;
}

std::vector<Eigen::Isometry3d> Detector::Impl::hypotheses(const std::vector<cv::linemod::Match>& matches,
                                                          const DetectionPrior& prior, std::vector<float>& similarity) {
  // Stage 1: the template poses of the best matches, shared out over the distances (small
  // templates are simple outlines that printed texture and clutter match as well as the
  // object does, and would take every place), each given a quick score: how much of its
  // outline an image edge supports within a few pixels, at the template's pose as it is.
  struct Candidate {
    Eigen::Isometry3d T;
    float similarity;
    int distance;
    double score;
  };
  std::vector<Candidate> candidates;
  const int n_dist = std::max(1, static_cast<int>(distances_m.size()));
  const int per_distance = std::max(2, (options.max_candidates + n_dist - 1) / n_dist);
  std::vector<int> taken(distances_m.size(), 0);
  detail::EdgeSupportOptions quick;
  quick.radius_px = options.candidate_radius_px;
  quick.step_px = 4.0;
  for (const auto& m : matches) {
    if (static_cast<int>(candidates.size()) >= options.max_candidates) break;
    const auto it = class_specs.find(m.class_id);
    if (it == class_specs.end() || m.template_id < 0 || m.template_id >= static_cast<int>(it->second.size())) continue;
    const auto& s = specs[static_cast<std::size_t>(it->second[static_cast<std::size_t>(m.template_id)])];
    if (s.distance >= static_cast<int>(taken.size()) || taken[static_cast<std::size_t>(s.distance)] >= per_distance) continue;
    const Eigen::Vector2d c(m.x + s.centre_dx, m.y + s.centre_dy);
    // The template shows the object on the optical axis; here it is seen along the ray to c:
    // turn the whole template pose by the rotation taking the axis onto that ray.
    const Eigen::Vector3d ray = camera.unproject(c).normalized();
    Eigen::Isometry3d T = template_pose(s.view, s.roll, s.distance_m);
    const Eigen::Matrix3d align = geometry::rotation_between(Eigen::Vector3d::UnitZ(), ray);
    T.linear() = align * T.linear();
    T.translation() = ray * s.distance_m - T.linear() * centre_obj;
    if (prior.up_cam && prior.up_obj && angle_deg(T.linear() * *prior.up_obj, *prior.up_cam) > options.up_tolerance_deg) continue;
    if (!turned_near(T.linear(), prior, template_turn_slack_deg())) continue;
    ++taken[static_cast<std::size_t>(s.distance)];
    visibility.compute(T, visible);
    const detail::EdgeSupport support = detail::edge_support(gradients, visible, quick);
    candidates.push_back({T, m.similarity, s.distance, support.share * static_cast<double>(support.supported)});
  }
  // Stage 2: the best scored, without the ones whose outline lies on a kept one's. Compared
  // by the projected model points as sets, so the views a symmetric object cannot tell apart
  // (a box turned half round) count as one. Shared out over the distances as stage 1 is: a
  // near template's long outline laid on dense texture outscores the object's own at its
  // distance (can development seed 6, frame 0: 300 against 130), and those would take every
  // place. Places a distance leaves are filled by the best of the rest.
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<int> distance_of(candidates.size());
  for (std::size_t i = 0; i < candidates.size(); ++i) distance_of[i] = candidates[i].distance;
  std::vector<std::vector<Eigen::Vector2d>> outlines;  // of the kept ones, in order
  std::vector<Eigen::Vector2d> outline;
  const auto kept = detail::hypothesis_places(distance_of, n_dist, options.max_hypotheses, [&](std::size_t i) {
    project_outline(candidates[i].T, outline);
    for (const auto& o : outlines)
      if (outline_distance_px(outline, o) < options.duplicate_px) return true;
    outlines.push_back(outline);
    return false;
  });
  std::vector<Eigen::Isometry3d> out;
  for (std::size_t i : kept) {
    out.push_back(candidates[i].T);
    similarity.push_back(candidates[i].similarity);
  }
  return out;
}

DetectionHypothesis Detector::Impl::refine(const Eigen::Isometry3d& start, float similarity) {
  DetectionHypothesis h;
  h.similarity = similarity;
  h.cam_T_obj = start;
  h.start_cam_T_obj = start;
  FrameReport report;
  pull.reset();
  for (int pass = 0; pass + 1 < options.refine_passes; ++pass) {
    pull.track(window_image, h.cam_T_obj, report);
    h.status = report.status;
    if (report.status == TrackStatus::Lost) break;
    h.cam_T_obj = report.cam_T_obj;
  }
  if (h.status != TrackStatus::Lost || options.refine_passes <= 1) {
    tracker.reset();
    tracker.track(window_image, h.cam_T_obj, report);
    h.status = report.status;
    if (report.status != TrackStatus::Lost) h.cam_T_obj = report.cam_T_obj;
  }
  return measure(h);
}

DetectionHypothesis Detector::Impl::measure(DetectionHypothesis h, bool whole_object) {
  // Like its templates, a detection must see the whole object: a pose that puts part of the
  // model outside the image is verified on a clipped outline, which clutter at the border
  // supports as readily as the object (late_entry: a box on the wall's printed rectangles).
  project_outline(h.cam_T_obj, scratch_outline);
  const bool whole = scratch_outline.size() == outline_obj.size() &&
                     std::all_of(scratch_outline.begin(), scratch_outline.end(), [&](const Eigen::Vector2d& p) { return camera.in_image(p); });
  if (whole_object && !whole) {
    h.support = h.score = 0;
    return h;
  }
  visibility.compute(h.cam_T_obj, visible);
  detail::EdgeSupportOptions so;
  so.radius_px = options.support_radius_px;
  if (h.status != TrackStatus::Lost) {
    const detail::EdgeSupport support = detail::edge_support(gradients, visible, so);
    h.support = support.share;
    h.score = support.share * static_cast<double>(support.supported);
    h.supported_px = static_cast<double>(support.supported) * so.step_px;
    h.unsupported_edge_share = support.unsupported_edge_share;
    h.weakest_edge_support = support.weakest_edge_support;
    h.colour_continuation = detail::colour_continuation(colour, visible).ratio;
  }
  return h;
}

unsigned failed_detection_tests(const DetectionHypothesis& h, const DetectorOptions& o) {
  unsigned failed = 0;
  if (!(h.support >= o.min_support)) failed |= kTooLittleSupport;
  if (!(h.supported_px >= o.min_supported_px)) failed |= kTooShortOutline;
  if (h.colour_continuation > o.max_colour_continuation) failed |= kOutlineRunsOn;
  if (!(h.unsupported_edge_share <= o.max_unsupported_edge_share)) failed |= kUnsupportedEdges;
  return failed;
}

void Detector::Impl::choose_symmetric(DetectionHypothesis& h, const DetectionPrior& prior) const {
  if (symmetries.empty()) return;
  if (const auto& like = prior.orient_like ? prior.orient_like : prior.near_cam_T_obj; like)
    h.cam_T_obj = symmetric_nearest(h.cam_T_obj, symmetries, *like);
  else if (prior.up_cam && prior.up_obj)
    h.cam_T_obj = symmetric_upright(h.cam_T_obj, symmetries, *prior.up_obj, *prior.up_cam);
}

Detector::Detector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Detector::~Detector() = default;
int Detector::template_count() const { return static_cast<int>(impl_->specs.size()); }
bool Detector::loaded_from_cache() const { return impl_->from_cache; }
const std::string& Detector::cache_path() const { return impl_->cache_path; }
double Detector::build_s() const { return impl_->build_s; }
const std::vector<std::string>& Detector::warnings() const { return impl_->warnings; }

std::expected<cv::Mat, std::string> Detector::Impl::take_frame(const cv::Mat& frame) {
  if (frame.empty() || frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3))
    return std::unexpected("detect: the frame must be 8-bit grey or BGR");
  if (frame.cols != camera.width_px() || frame.rows != camera.height_px())
    return std::unexpected("detect: the frame is " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                           " but the calibration is " + std::to_string(camera.width_px()) + "x" +
                           std::to_string(camera.height_px()));
  if (auto ok = window_image.assign(frame); !ok) return std::unexpected("detect: " + ok.error());
  cv::Mat grey, bgr;
  if (frame.channels() == 1) {
    grey = frame;
    cv::cvtColor(frame, bgr, cv::COLOR_GRAY2BGR);
  } else {
    bgr = frame;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  }
  gradients.compute(grey);
  bgr.copyTo(colour);
  const int pad_x = (kPadMultiple - bgr.cols % kPadMultiple) % kPadMultiple;
  const int pad_y = (kPadMultiple - bgr.rows % kPadMultiple) % kPadMultiple;
  if (pad_x || pad_y) cv::copyMakeBorder(bgr, bgr, 0, pad_y, 0, pad_x, cv::BORDER_REPLICATE);
  return bgr;
}

std::expected<DetectionHypothesis, std::string> Detector::verify(const cv::Mat& frame, const Eigen::Isometry3d& cam_T_obj) {
  if (auto ok = impl_->take_frame(frame); !ok) return std::unexpected(ok.error());
  DetectionHypothesis h;
  h.cam_T_obj = h.start_cam_T_obj = cam_T_obj;
  h.status = TrackStatus::Tracked;
  return impl_->measure(h, false);
}

std::expected<DetectionResult, std::string> Detector::detect(const cv::Mat& frame, const DetectionPrior& prior) {
  Impl& d = *impl_;
  DetectionResult result;
  const auto t0 = Clock::now();
  auto bgr = d.take_frame(frame);
  if (!bgr) return std::unexpected(bgr.error());
  // Near the prediction first: when the object is where it was expected, no search is needed.
  if (prior.near_cam_T_obj) {
    const auto t_near = Clock::now();
    DetectionHypothesis near = d.refine(*prior.near_cam_T_obj, 0.0f);
    result.refine_ms += ms_since(t_near);
    if (prior.cam_R_obj) near.turn_off_deg = d.turn_off_deg(near.cam_T_obj.linear(), prior);
    if (d.verified(near) && d.turned_near(near.cam_T_obj.linear(), prior, 0)) {
      result.best = near;
      result.found = true;
      result.hypotheses.push_back(near);
      return result;
    }
    result.hypotheses.push_back(near);
  }

  const std::vector<std::string> classes = d.classes_for(prior);
  for (const auto& id : classes) result.templates_matched += static_cast<int>(d.class_specs.at(id).size());
  std::vector<cv::linemod::Match> matches;
  if (!classes.empty()) d.line2d->match({*bgr}, d.options.min_similarity, matches, classes);
  result.matches = static_cast<int>(matches.size());
  std::vector<float> similarity;
  const std::vector<Eigen::Isometry3d> starts = d.hypotheses(matches, prior, similarity);
  result.match_ms = ms_since(t0) - result.refine_ms;

  const auto t1 = Clock::now();
  for (std::size_t i = 0; i < starts.size(); ++i) result.hypotheses.push_back(d.refine(starts[i], similarity[i]));
  std::stable_sort(result.hypotheses.begin(), result.hypotheses.end(),
                   [](const DetectionHypothesis& a, const DetectionHypothesis& b) { return a.score > b.score; });
  result.refine_ms += ms_since(t1);
  for (DetectionHypothesis& h : result.hypotheses) d.choose_symmetric(h, prior);
  if (prior.cam_R_obj) {
    // A pose turned away from the known orientation is no candidate at all, whatever its score:
    // the search was narrowed to templates near it, and refinement can still turn onto clutter.
    for (DetectionHypothesis& h : result.hypotheses) h.turn_off_deg = d.turn_off_deg(h.cam_T_obj.linear(), prior);
    std::stable_partition(result.hypotheses.begin(), result.hypotheses.end(),
                          [&](const DetectionHypothesis& h) { return d.turned_near(h.cam_T_obj.linear(), prior, 0); });
  }
  if (!result.hypotheses.empty()) {
    result.best = result.hypotheses.front();
    result.found = d.verified(result.best) && d.turned_near(result.best.cam_T_obj.linear(), prior, 0);
  }
  return result;
}

}  // namespace epichead::vision
