// Ellipse tracker benchmarks: one ellipse (a disc of semi axes 70 x 45 px on a cluttered,
// noisy colour background), 30 tracker lines of 60 px: sampling + edgels + interval cues +
// likelihoods + RANSAC ellipse candidates + selection + arc update + reference update.
// `ellipse_occluded`: the same with a third of the rim hidden (an arc with its two extension lines).
#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench.h"
#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/window_image.h"

namespace epichead::bench {
namespace {

using namespace epichead::vision;

Ellipse disc_ellipse() {
  Ellipse e;
  e.centre_px = {160.3, 120.6};
  e.semi_major_px = 70;
  e.semi_minor_px = 45;
  e.angle_rad = 0.4;
  return e;
}

cv::Mat scene(bool occluded) {
  cv::Mat img(240, 320, CV_8UC3);
  cv::RNG blocks(5);
  for (int y = 0; y < img.rows; y += 12)
    for (int x = 0; x < img.cols; x += 12)
      cv::rectangle(img, {x, y}, {x + 11, y + 11},
                    cv::Scalar(blocks.uniform(40, 250), blocks.uniform(40, 250), blocks.uniform(40, 250)), cv::FILLED);
  const Ellipse e = disc_ellipse();
  cv::ellipse(img, cv::RotatedRect(cv::Point2f(static_cast<float>(e.centre_px.x()), static_cast<float>(e.centre_px.y())),
                                   cv::Size2f(static_cast<float>(2 * e.semi_major_px), static_cast<float>(2 * e.semi_minor_px)),
                                   static_cast<float>(e.angle_rad * 180 / CV_PI)),
              cv::Scalar(40, 60, 110), cv::FILLED, cv::LINE_AA);
  if (occluded) cv::rectangle(img, cv::Point(200, 0), cv::Point(319, 239), cv::Scalar(200, 205, 210), cv::FILLED);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0);
  cv::Mat noise(img.size(), CV_16SC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 2);
  cv::add(img, noise, img, cv::noArray(), CV_8UC3);
  return img;
}

struct State {
  WindowImage image;
  EllipseTracker tracker;
  WindowPlacement placement;
  State(EpicMode mode, bool occluded) : tracker([mode] { EllipseTrackerOptions o; o.mode = mode; return o; }()) {
    (void)image.assign(scene(occluded));
    // Occluded: track from the previous result so the lines stay on the arc; else re-project.
    placement = occluded ? WindowPlacement::Previous : WindowPlacement::Projection;
    for (int k = 0; k < 3; ++k) run();  // the arc settles; buffers are reserved
  }
  void run() { tracker.track_one(image, 0, disc_ellipse(), placement); }
};

const Registration ellipse{"ellipse", [] {
  auto s = std::make_shared<State>(EpicMode::Epic, false);
  return [s] { s->run(); };
}};

const Registration ellipse_gradient{"ellipse_gradient", [] {
  auto s = std::make_shared<State>(EpicMode::Gradient, false);
  return [s] { s->run(); };
}};

const Registration ellipse_occluded{"ellipse_occluded", [] {
  auto s = std::make_shared<State>(EpicMode::Epic, true);
  return [s] { s->run(); };
}};

}  // namespace
}  // namespace epichead::bench
