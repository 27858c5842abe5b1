// Benchmarks visibility_teabox and visibility_300: one full visibility computation.
#include <cmath>
#include <memory>

#include "bench/bench.h"
#include "bench/box_models.h"
#include "epichead/vision/look_at.h"
#include "epichead/vision/visibility.h"

namespace {

using namespace epichead::vision;



struct VisibilityBench {
  CadModel model;
  Camera camera{640, 480, {600, 600, 320, 240}};
  std::unique_ptr<Visibility> visibility;
  VisibleModel out;
  Eigen::Isometry3d pose;
};

// The teabox of ../shared/data/teabox (0.165 x 0.068 x 0.08 m) at its frame-0 pose.
const epichead::bench::Registration teabox{"visibility_teabox", [] {
  auto b = std::make_shared<VisibilityBench>();
  b->model = epichead::bench::teabox_model();
  b->camera = Camera(640, 480, {839.2147, 839.44555, 325.66776, 243.69727});
  b->pose = Eigen::Isometry3d::Identity();
  b->pose.linear() = Eigen::Quaterniond(0.479187837, 0.712274104, 0.452593677, -0.241254183).normalized().toRotationMatrix();
  b->pose.translation() = Eigen::Vector3d(-0.070345888, -0.084143195, 0.448947131);
  b->visibility = std::make_unique<Visibility>(b->model, b->camera);
  return [b] { b->visibility->compute(b->pose, b->out); };
}};

// 25 boxes on a 5 x 5 grid (300 edges, 150 faces), seen obliquely so that they hide each other.
const epichead::bench::Registration grid300{"visibility_300", [] {
  auto b = std::make_shared<VisibilityBench>();
  b->model = epichead::bench::box_grid_300_model();
  b->pose = look_at({-0.5, -0.4, 0.45}, {0.26, 0.26, 0.03}).inverse();
  b->visibility = std::make_unique<Visibility>(b->model, b->camera);
  return [b] { b->visibility->compute(b->pose, b->out); };
}};

}  // namespace
