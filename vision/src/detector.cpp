#include "epichead/vision/detector.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <atomic>
#include <map>
#include <thread>

#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd/linemod.hpp>

#include "edge_drawing.h"
#include "edge_support.h"
#include "template_cache.h"
#include "view_sphere.h"

namespace epichead::vision {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

// The query image is padded to a multiple of 16 so that LINE-2D's two pyramid levels divide
// into its T-sized cells.
constexpr int kPadMultiple = 16;
// Templates are bumped whenever what they contain changes (rendering, features, layout).
constexpr std::uint64_t kTemplateFormat = 1;

struct Hash {
  std::uint64_t h = 1469598103934665603ull;
  void bytes(const void* p, std::size_t n) {
    const auto* c = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) { bytes(&v, sizeof v); }
};

// Object centre (the middle of its bounding box) and the radius of the sphere about it that
// holds the model.
void model_extent(const CadModel& model, Eigen::Vector3d& centre, double& radius) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  auto add = [&](const Eigen::Vector3d& p) { lo = lo.cwiseMin(p); hi = hi.cwiseMax(p); };
  for (const auto& v : model.vertices) add(v);
  for (const auto& c : model.circles) {
    add(c.centre_obj + Eigen::Vector3d::Constant(c.radius_m));
    add(c.centre_obj - Eigen::Vector3d::Constant(c.radius_m));
  }
  centre = (lo + hi) / 2;
  radius = (hi - lo).norm() / 2;
}

std::string class_id(int view, int roll) { return "v" + std::to_string(view) + "r" + std::to_string(roll); }

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

std::string default_template_cache_dir() {
  namespace fs = std::filesystem;
  if (const char* d = std::getenv("EPICHEAD_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return (fs::path(d) / "epichead").string();
  if (const char* d = std::getenv("HOME"); d && *d) return (fs::path(d) / ".cache" / "epichead").string();
  return {};
}

struct Detector::Impl {
  Impl(const CadModel& m, const Camera& c, const DetectorOptions& o, const ModelTrackerOptions& t)
      : model_storage(m), model(&model_storage), camera(c), options(o), pull(model_storage, c, wide(t)),
        tracker(model_storage, c, t), visibility(model_storage, c, t.visibility) {}

  // The pull's windows are twice as wide as tracking's: a template's pose can be off by more
  // than a frame's motion.
  static ModelTrackerOptions wide(ModelTrackerOptions t) {
    t.lines.window.width_px = std::min(kMaxWindowWidth, 2 * t.lines.window.width_px);
    t.max_jump_px = 2 * t.max_jump_px;
    return t;
  }

  // The detector keeps its own copy of the model: the trackers and visibility refer to it, and
  // the caller's may go (the onboard loop takes the detector over).
  CadModel model_storage;
  const CadModel* model;
  Camera camera;
  DetectorOptions options;
  // A template's pose is up to half a grid step off in view, turn and distance: a tracker with
  // wide windows pulls it in first; the caller's tracker then measures it as tracking will.
  ModelTracker pull;
  ModelTracker tracker;
  Visibility visibility;
  VisibleModel visible;
  WindowImage window_image;
  detail::EdgeGradients gradients;
  cv::Ptr<cv::linemod::Detector> line2d;
  std::vector<Eigen::Vector3d> views;
  std::vector<double> rolls_rad;
  std::vector<double> distances_m;
  std::vector<detail::TemplateSpec> specs;
  std::map<std::string, std::vector<int>> class_specs;  // class id -> spec index per template id
  Eigen::Vector3d centre_obj = Eigen::Vector3d::Zero();
  double radius_m = 0;
  std::vector<Eigen::Vector3d> outline_obj;  // model points whose projections stand for a pose's outline
  std::vector<Eigen::Vector2d> scratch_outline;

  void project_outline(const Eigen::Isometry3d& T, std::vector<Eigen::Vector2d>& px) const {
    px.clear();
    for (const auto& p : outline_obj) {
      const Eigen::Vector3d q = T * p;
      if (q.z() > 1e-6) px.push_back(camera.project(q));
    }
  }
  std::string cache_path;
  bool from_cache = false;
  double build_s = 0;
  std::vector<std::string> warnings;

  std::uint64_t key() const;
  // LINE-2D on colour gradients (a drawing of white edges gives the same orientations as a
  // grey frame's gradients, and the matcher takes BGR): T = 5 px at full resolution, 8 px at half.
  cv::Ptr<cv::linemod::Detector> make_matcher() const {
    std::vector<cv::Ptr<cv::linemod::Modality>> modalities{
        cv::makePtr<cv::linemod::ColorGradient>(10.0f, static_cast<std::size_t>(options.features_per_template), 55.0f)};
    return cv::makePtr<cv::linemod::Detector>(modalities, std::vector<int>{5, 8});
  }
  void grids();
  std::vector<detail::TemplateRecord> render(const Progress& progress);
  void load(const std::vector<detail::TemplateRecord>& records);
  Eigen::Isometry3d template_pose(int view, int roll, double distance_m) const;
  std::vector<std::string> classes_for(const DetectionPrior& prior) const;
  std::vector<Eigen::Isometry3d> hypotheses(const std::vector<cv::linemod::Match>& matches, const DetectionPrior& prior,
                                            std::vector<float>& similarity);
  DetectionHypothesis refine(const Eigen::Isometry3d& start, float similarity);
  // Support, score and outline length of h's pose on the current frame (gradients).
  // whole_object: a pose with part of the model outside the image scores 0 (detections).
  DetectionHypothesis measure(DetectionHypothesis h, bool whole_object = true);
  // Takes a frame: the matcher's BGR (padded), the grey gradients and the tracker's image.
  std::expected<cv::Mat, std::string> take_frame(const cv::Mat& frame);
  bool verified(const DetectionHypothesis& h) const {
    return h.support >= options.min_support && h.supported_px >= options.min_supported_px;
  }
};

std::uint64_t Detector::Impl::key() const {
  Hash h;
  h.value(kTemplateFormat);
  const std::string cao = to_cao(*model);
  h.bytes(cao.data(), cao.size());
  h.value(camera.width_px());
  h.value(camera.height_px());
  const Eigen::Matrix3d K = camera.K();
  h.bytes(K.data(), sizeof(double) * 9);
  const auto& d = camera.distortion();
  h.bytes(&d, sizeof d);
  h.value(options.view_subdivisions);
  h.value(options.in_plane_step_deg);
  for (double m : distances_m) h.value(m);
  h.value(options.features_per_template);
  return h.h;
}

void Detector::Impl::grids() {
  model_extent(*model, centre_obj, radius_m);
  // At most 64 points: the vertices (every k-th), and eight points on each circle.
  const std::size_t step = std::max<std::size_t>(1, model->vertices.size() / 64);
  for (std::size_t i = 0; i < model->vertices.size(); i += step) outline_obj.push_back(model->vertices[i]);
  for (const auto& c : model->circles) {
    const Eigen::Vector3d u = c.normal_obj.unitOrthogonal(), v = c.normal_obj.normalized().cross(u);
    for (int k = 0; k < 8; ++k)
      outline_obj.push_back(c.centre_obj + c.radius_m * (std::cos(k * M_PI / 4) * u + std::sin(k * M_PI / 4) * v));
  }
  views = detail::view_directions(options.view_subdivisions);
  const int rolls = std::max(1, static_cast<int>(std::lround(360.0 / options.in_plane_step_deg)));
  for (int r = 0; r < rolls; ++r) rolls_rad.push_back(2 * M_PI * r / rolls);
  double lo = options.min_distance_m, hi = options.max_distance_m;
  const double f = 0.5 * (camera.intrinsics().fx_px + camera.intrinsics().fy_px);
  const double side = std::min(camera.width_px(), camera.height_px());
  if (!(lo > 0)) lo = 2 * radius_m * f / (options.max_span * side);
  if (!(hi > 0)) hi = 2 * radius_m * f / (options.min_span * side);
  distances_m.clear();
  for (double d = lo; d <= hi * 1.0001 && distances_m.size() < 64; d *= options.distance_ratio) distances_m.push_back(d);
}

Eigen::Isometry3d Detector::Impl::template_pose(int view, int roll, double distance_m) const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = detail::look_rotation(views[static_cast<std::size_t>(view)], rolls_rad[static_cast<std::size_t>(roll)]);
  T.translation() = Eigen::Vector3d(0, 0, distance_m) - T.linear() * centre_obj;
  return T;
}

std::vector<detail::TemplateRecord> Detector::Impl::render(const Progress& progress) {
  // Views are shared out over threads (each with its own visibility and matcher, which are not
  // thread-safe) and their records put back in view order, so the result does not depend on
  // the thread count.
  const int n_views = static_cast<int>(views.size());
  const int total = static_cast<int>(views.size() * rolls_rad.size() * distances_m.size());
  std::vector<std::vector<detail::TemplateRecord>> per_view(views.size());
  std::atomic<int> done{0};
  const Eigen::Vector2d centre_px(camera.intrinsics().cx_px, camera.intrinsics().cy_px);
  auto work = [&](int first, int stride) {
    Visibility vis(*model, camera, visibility.options());
    VisibleModel seen;
    auto matcher = make_matcher();
    for (int v = first; v < n_views; v += stride)
      for (int r = 0; r < static_cast<int>(rolls_rad.size()); ++r) {
        const std::string id = class_id(v, r);
        for (int k = 0; k < static_cast<int>(distances_m.size()); ++k, ++done) {
          vis.compute(template_pose(v, r, distances_m[static_cast<std::size_t>(k)]), seen);
          const detail::EdgeDrawing drawing = detail::draw_edges(seen, camera, 6);
          if (drawing.empty) continue;
          cv::Rect box;
          const int tid = matcher->addTemplate({drawing.bgr}, id, drawing.mask, &box);
          if (tid < 0) continue;  // too few features: nothing to match by
          detail::TemplateRecord rec;
          rec.spec = {v, r, k, static_cast<float>(distances_m[static_cast<std::size_t>(k)]),
                      static_cast<float>(centre_px.x() - (drawing.origin.x + box.x)),
                      static_cast<float>(centre_px.y() - (drawing.origin.y + box.y))};
          rec.levels = matcher->getTemplates(id, tid);
          per_view[static_cast<std::size_t>(v)].push_back(std::move(rec));
        }
      }
  };
  const int threads = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(work, t, threads);
  std::thread own(work, 0, threads);
  while (progress && done.load() < total) {
    progress(done.load(), total);
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  own.join();
  for (auto& t : pool) t.join();
  if (progress) progress(total, total);
  std::vector<detail::TemplateRecord> records;
  for (auto& list : per_view)
    for (auto& rec : list) records.push_back(std::move(rec));
  return records;
}

void Detector::Impl::load(const std::vector<detail::TemplateRecord>& records) {
  specs.clear();
  class_specs.clear();
  for (const auto& rec : records) {
    const std::string id = class_id(rec.spec.view, rec.spec.roll);
    // Templates of a class get ids 0, 1, ... in the order added: the spec list follows it.
    const int tid = line2d->addSyntheticTemplate(rec.levels, id);
    auto& list = class_specs[id];
    if (tid != static_cast<int>(list.size())) continue;
    list.push_back(static_cast<int>(specs.size()));
    specs.push_back(rec.spec);
  }
}

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
    const Eigen::Matrix3d align = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), ray).toRotationMatrix();
    T.linear() = align * T.linear();
    T.translation() = ray * s.distance_m - T.linear() * centre_obj;
    if (prior.up_cam && prior.up_obj && angle_deg(T.linear() * *prior.up_obj, *prior.up_cam) > options.up_tolerance_deg) continue;
    ++taken[static_cast<std::size_t>(s.distance)];
    visibility.compute(T, visible);
    const detail::EdgeSupport support = detail::edge_support(gradients, visible, quick);
    candidates.push_back({T, m.similarity, support.share * static_cast<double>(support.supported)});
  }
  // Stage 2: the best scored, without the ones whose outline lies on a kept one's. Compared
  // by the projected model points as sets, so the views a symmetric object cannot tell apart
  // (a box turned half round) count as one.
  std::stable_sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<Eigen::Isometry3d> out;
  std::vector<std::vector<Eigen::Vector2d>> outlines;
  std::vector<Eigen::Vector2d> outline;
  for (const auto& c : candidates) {
    if (static_cast<int>(out.size()) >= options.max_hypotheses) break;
    project_outline(c.T, outline);
    bool near_kept = false;
    for (std::size_t k = 0; k < out.size() && !near_kept; ++k)
      near_kept = outline_distance_px(outline, outlines[k]) < options.duplicate_px;
    if (near_kept) continue;
    outlines.push_back(outline);
    out.push_back(c.T);
    similarity.push_back(c.similarity);
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
  }
  return h;
}

Detector::Detector(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Detector::~Detector() = default;
int Detector::template_count() const { return static_cast<int>(impl_->specs.size()); }
bool Detector::loaded_from_cache() const { return impl_->from_cache; }
const std::string& Detector::cache_path() const { return impl_->cache_path; }
double Detector::build_s() const { return impl_->build_s; }
const std::vector<std::string>& Detector::warnings() const { return impl_->warnings; }

std::expected<std::unique_ptr<Detector>, std::string> Detector::create(const CadModel& model, const Camera& camera,
                                                                        const DetectorOptions& options,
                                                                        const ModelTrackerOptions& tracking,
                                                                        const std::string& cache_dir, const Progress& progress) {
  if (options.view_subdivisions < 0 || options.view_subdivisions > 4)
    return std::unexpected("detector: view subdivisions must be 0..4, got " + std::to_string(options.view_subdivisions));
  if (!(options.in_plane_step_deg >= 1 && options.in_plane_step_deg <= 180))
    return std::unexpected("detector: in-plane step must be 1..180 deg");
  if (!(options.distance_ratio > 1.01 && options.distance_ratio < 4)) return std::unexpected("detector: distance ratio must be 1.01..4");
  if (options.min_distance_m < 0 || options.max_distance_m < 0 ||
      (options.min_distance_m > 0 && options.max_distance_m > 0 && options.max_distance_m < options.min_distance_m))
    return std::unexpected("detector: the distance range must be 0 < min <= max (m)");
  if (model.vertices.empty() && model.circles.empty()) return std::unexpected("detector: the model has no points or circles");
  const auto t0 = Clock::now();
  auto impl = std::make_unique<Impl>(model, camera, options, tracking);
  impl->grids();
  if (impl->radius_m <= 0 || !std::isfinite(impl->radius_m)) return std::unexpected("detector: the model has no extent");
  impl->line2d = impl->make_matcher();

  const std::uint64_t key = impl->key();
  char name[64];
  std::snprintf(name, sizeof name, "templates-%016llx.bin", static_cast<unsigned long long>(key));
  if (!cache_dir.empty()) impl->cache_path = (std::filesystem::path(cache_dir) / name).string();
  std::vector<detail::TemplateRecord> records;
  if (!impl->cache_path.empty() && std::filesystem::exists(impl->cache_path)) {
    auto cached = detail::read_template_cache(impl->cache_path, key);
    if (cached) {
      records = std::move(*cached);
      impl->from_cache = true;
    } else {
      impl->warnings.push_back(cached.error() + " (templates rebuilt)");
    }
  }
  if (!impl->from_cache) {
    records = impl->render(progress);
    if (records.empty()) return std::unexpected("detector: no template could be made (is the model visible at the distances tried?)");
    if (!impl->cache_path.empty())
      if (auto ok = detail::write_template_cache(impl->cache_path, key, records); !ok)
        impl->warnings.push_back(ok.error() + " (templates not cached)");
  }
  impl->load(records);
  impl->build_s = ms_since(t0) * 1e-3;
  return std::unique_ptr<Detector>(new Detector(std::move(impl)));
}

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
    if (d.verified(near)) {
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
  if (!result.hypotheses.empty()) {
    result.best = result.hypotheses.front();
    result.found = d.verified(result.best);
  }
  return result;
}

}  // namespace epichead::vision
