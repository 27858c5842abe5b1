// Detection's screening (DetectorOptions::screen_passes, refined_hypotheses): every hypothesis
// takes the first tracking steps, only the best few the rest. The speed-up must not change what
// is found: on a rendered frame of a box on a textured background the screened search finds
// the same pose as refining every hypothesis to the end, and that pose is the true one.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "epichead/vision/cao_model.h"
#include "epichead/vision/detector.h"
#include "view_sphere.h"

using namespace epichead::vision;

namespace {

CadModel box(double x, double y, double z) {
  RawModel raw;
  raw.vertices = {{0, 0, 0}, {x, 0, 0}, {x, y, 0}, {0, y, 0}, {0, 0, z}, {x, 0, z}, {x, y, z}, {0, y, z}};
  raw.face_loops = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  auto m = build_model(raw, "box");
  REQUIRE(m);
  return *m;
}

// The box's faces painted far to near in three shades over blotchy grey texture (so that
// the background has gradients of every orientation, as a real one does).
cv::Mat render(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& cam_T_obj) {
  cv::Mat frame(camera.height_px(), camera.width_px(), CV_8UC1);
  cv::RNG rng(7);
  cv::Mat noise(frame.rows / 16, frame.cols / 16, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 60, 140);
  cv::resize(noise, frame, frame.size(), 0, 0, cv::INTER_CUBIC);
  struct Face {
    double depth;
    std::vector<cv::Point> px;
    int shade;
  };
  std::vector<Face> faces;
  for (const auto& f : model.faces) {
    Face face{0, {}, 0};
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int v : f.vertices) {
      const Eigen::Vector3d p = cam_T_obj * model.vertices[static_cast<std::size_t>(v)];
      const Eigen::Vector2d q = camera.project(p);
      face.px.emplace_back(static_cast<int>(std::lround(q.x())), static_cast<int>(std::lround(q.y())));
      mean += p;
    }
    face.depth = mean.z() / static_cast<double>(f.vertices.size());
    face.shade = 170 + 30 * static_cast<int>(faces.size() % 3);
    faces.push_back(face);
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) { return a.depth > b.depth; });
  for (const auto& f : faces) cv::fillConvexPoly(frame, f.px, cv::Scalar(f.shade), cv::LINE_AA);
  return frame;
}

// Mean distance from each projected model point to the nearest of the other pose's, both
// ways: 0 for poses that draw the same outline, whichever of a box's half turns they are.
double outline_px(const CadModel& model, const Camera& camera, const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  std::vector<Eigen::Vector2d> pa, pb;
  for (const auto& v : model.vertices) {
    pa.push_back(camera.project(a * v));
    pb.push_back(camera.project(b * v));
  }
  auto one_way = [](const std::vector<Eigen::Vector2d>& p, const std::vector<Eigen::Vector2d>& q) {
    double sum = 0;
    for (const auto& x : p) {
      double best = 1e300;
      for (const auto& y : q) best = std::min(best, (x - y).norm());
      sum += best;
    }
    return sum / static_cast<double>(p.size());
  };
  return 0.5 * (one_way(pa, pb) + one_way(pb, pa));
}

}  // namespace

TEST_CASE("detection: screening the hypotheses finds the same pose as refining every one to the end, the true one") {
  const CadModel model = box(0.2, 0.15, 0.1);
  const Camera camera(640, 480, Intrinsics{600, 600, 320, 240});
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = epichead::vision::detail::look_rotation(Eigen::Vector3d(1, -2, 1.5).normalized(), 0.3);
  truth.translation() = Eigen::Vector3d(0.03, -0.02, 0.75) - truth.linear() * Eigen::Vector3d(0.1, 0.075, 0.05);
  const cv::Mat frame = render(model, camera, truth);

  // A coarse template grid keeps the test quick; the search is the default one.
  DetectorOptions fast;
  fast.view_subdivisions = 1;
  fast.in_plane_step_deg = 30;
  DetectorOptions exhaustive = fast;
  exhaustive.screen_passes = 0;
  exhaustive.refined_hypotheses = exhaustive.max_hypotheses;
  REQUIRE(fast.refined_hypotheses < fast.max_hypotheses);

  auto fast_detector = Detector::create(model, camera, fast, {}, "");
  REQUIRE(fast_detector);
  auto exhaustive_detector = Detector::create(model, camera, exhaustive, {}, "");
  REQUIRE(exhaustive_detector);
  const auto found_fast = (*fast_detector)->detect(frame);
  const auto found_all = (*exhaustive_detector)->detect(frame);
  REQUIRE(found_fast);
  REQUIRE(found_all);
  REQUIRE(found_all->found);
  REQUIRE(found_fast->found);
  CHECK(outline_px(model, camera, found_all->best.cam_T_obj, truth) < 1.5);
  CHECK(outline_px(model, camera, found_fast->best.cam_T_obj, truth) < 1.5);
  CHECK(outline_px(model, camera, found_fast->best.cam_T_obj, found_all->best.cam_T_obj) < 1.0);
  CHECK(found_fast->best.support >= found_all->best.support - 0.02);
  // Only the screened best were refined to the end.
  CHECK(found_fast->hypotheses.size() == found_all->hypotheses.size());
}
