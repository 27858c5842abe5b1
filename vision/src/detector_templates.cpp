// Detection templates: the view grid, rendering the model's edges at each pose into LINE-2D
// templates (on every core), the cache, and Detector::create.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "detector_impl.h"
#include "edge_drawing.h"
#include "view_sphere.h"

namespace epichead::vision {

using detail::class_id;
using detail::Clock;
using detail::ms_since;

namespace {

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

}  // namespace

std::string default_template_cache_dir() {
  namespace fs = std::filesystem;
  if (const char* d = std::getenv("EPICHEAD_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d) return (fs::path(d) / "epichead").string();
  if (const char* d = std::getenv("HOME"); d && *d) return (fs::path(d) / ".cache" / "epichead").string();
  return {};
}

std::uint64_t Detector::Impl::key() const {
  Hash h;
  h.value(kTemplateFormat);
  const std::string cao = to_cao(*model);
  h.bytes(cao.data(), cao.size());
  h.value(camera.width_px());
  h.value(camera.height_px());
  const Eigen::Matrix3d K = camera.K();
  h.bytes(K.data(), sizeof(double) * 9);
  const auto& d = camera.distortion();  // all 14 of OpenCV's coefficients: a tilt changes the templates too
  h.bytes(d.data(), sizeof(double) * d.size());
  h.value(static_cast<int>(camera.lens()));
  h.value(options.view_subdivisions);
  h.value(options.in_plane_step_deg);
  for (double m : distances_m) h.value(m);
  h.value(options.features_per_template);
  return h.h;
}

void Detector::Impl::grids() {
  model_extent(*model, centre_obj, radius_m);
  outline_obj = outline_points(*model);
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

}  // namespace epichead::vision
