#include "detection_setup.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "progress.h"

namespace epichead::tools {

void add_detection_options(CLI::App& app, DetectionArgs& a) {
  app.add_option("--cache-dir", a.cache_dir,
                 "Where detection templates are cached, per model and camera (default $EPICHEAD_CACHE_DIR, "
                 "$XDG_CACHE_HOME/epichead or ~/.cache/epichead)");
  app.add_flag("--no-cache", a.no_cache, "Build the detection templates without reading or writing the cache");
  app.add_option("--object-up", a.object_up,
                 "The object's up direction in its model frame, x,y,z, when it stands on its base: with the IMU, "
                 "gravity then removes two of the three rotation degrees of freedom from the detection search, and "
                 "track checks every pose's tilt against it from the first frame instead of learning the object's "
                 "down from the poses");
  app.add_option("--distance-m", a.options.min_distance_m, "Detection: the nearest object distance to search, m (default from the model's size)")
      ->check(CLI::Range(0.0, 1e3));
  app.add_option("--max-distance-m", a.options.max_distance_m, "Detection: the farthest object distance to search, m")
      ->check(CLI::Range(0.0, 1e3));
  app.add_option("--views", a.options.view_subdivisions,
                 "Detection: view sphere subdivisions (0: 12 views, 1: 42, 2: 162, 3: 642, 4: 2562)")
      ->check(CLI::Range(0, 4));
  app.add_option("--hypotheses", a.options.max_hypotheses,
                 "Detection: hypotheses refined and verified per search (more: slower, finds more)")
      ->check(CLI::Range(1, 10000));
  app.add_option("--min-support", a.options.min_support,
                 "Detection: share of the model's outline an image edge must support for a pose to count as found")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--max-colour-continuation", a.options.max_colour_continuation,
                 "Detection: how much the colours across the outline's lines may still differ past the object's "
                 "corners, relative to along it, for a pose to count as found (a model laid on a facade's lines "
                 "finds them running on; 2 turns the test off)")
      ->check(CLI::Range(0.0, 2.0));
  app.add_option("--max-unsupported-edges", a.options.max_unsupported_edge_share,
                 "Detection: the largest share of the model's outline that may lie on edges an image edge "
                 "hardly supports (under a quarter of their length) for a pose to count as found (1 turns the test off)")
      ->check(CLI::Range(0.0, 1.0));
}

std::expected<std::unique_ptr<vision::Detector>, std::string> make_detector(const std::string& command,
                                                                            const vision::CadModel& model,
                                                                            const vision::Camera& camera,
                                                                            const DetectionArgs& args,
                                                                            const vision::ModelTrackerOptions& tracking) {
  // Building the templates takes tens of seconds the first time: progress on stderr when it is a
  // terminal (progress.h), nothing in a log. Read from the cache, the callback is never called.
  const std::string label = "epichead " + command + ": building detection templates";
  Progress shown(label.c_str(), "templates", 0);
  const vision::Detector::Progress progress = [&shown](int done, int total) {
    shown.set_total(total);
    shown.update(done);
  };
  auto detector = vision::Detector::create(model, camera, args.options, tracking, args.no_cache ? "" : args.cache_dir, progress);
  shown.finish();
  if (!detector) return detector;
  for (const auto& w : (*detector)->warnings()) std::fprintf(stderr, "epichead %s: warning: %s\n", command.c_str(), w.c_str());
  return detector;
}

std::expected<std::optional<Eigen::Vector3d>, std::string> object_up(const DetectionArgs& args) {
  if (args.object_up.empty()) return std::optional<Eigen::Vector3d>{};
  Eigen::Vector3d v;
  char c1 = 0, c2 = 0;
  std::istringstream in(args.object_up);
  if (!(in >> v.x() >> c1 >> v.y() >> c2 >> v.z()) || c1 != ',' || c2 != ',' || !(in >> std::ws).eof() || !v.allFinite() ||
      v.norm() < 1e-9)
    return std::unexpected("--object-up must be x,y,z, a non-zero direction, got '" + args.object_up + "'");
  return std::optional<Eigen::Vector3d>{v.normalized()};
}

std::optional<Eigen::Vector3d> up_from_imu(const std::vector<vision::ImuRecord>& imu, double t_s, double window_s) {
  const auto first = std::lower_bound(imu.begin(), imu.end(), t_s - window_s,
                                      [](const vision::ImuRecord& r, double t) { return r.t_s < t; });
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (auto it = first; it != imu.end() && it->t_s <= t_s + window_s; ++it)
    if (it->accel_mps2.allFinite()) {
      sum += it->accel_mps2;
      ++n;
    }
  if (n == 0 || sum.norm() / n < 1.0) return std::nullopt;
  return sum.normalized();
}

}  // namespace epichead::tools
