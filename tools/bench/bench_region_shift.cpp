// Without the IMU `epichead track` measures, each frame, how far the object's region moved since
// the previous frame (vision/region_shift.h): a 240 x 180 px region of a 640 x 480 colour frame,
// the size of a package seen at arm's length. Two views of a textured scene, 5 px apart,
// alternate so that every iteration correlates a real shift.
#include <array>
#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench.h"
#include "epichead/vision/region_shift.h"

namespace epichead::bench {
namespace {

struct Shifts {
  std::array<cv::Mat, 2> frames;
  vision::RegionShiftEstimator estimator;
  int next = 0;
  double sum_px = 0;
};

Iteration region_shift() {
  auto s = std::make_shared<Shifts>();
  cv::Mat world(520, 680, CV_8UC3);
  cv::RNG rng(11);
  rng.fill(world, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(world, world, cv::Size(0, 0), 2.0);
  s->frames[0] = world(cv::Rect(10, 10, 640, 480)).clone();
  s->frames[1] = world(cv::Rect(15, 13, 640, 480)).clone();
  const cv::Rect region(200, 150, 240, 180);
  (void)s->estimator.push(s->frames[1], region);
  return [s, region] {
    if (const auto shift = s->estimator.push(s->frames[s->next], region)) s->sum_px += shift->shift_px.x();
    s->next ^= 1;
  };
}

const Registration shift{"region_shift_240x180", region_shift};

}  // namespace
}  // namespace epichead::bench
