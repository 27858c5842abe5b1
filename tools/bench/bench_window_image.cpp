// The per-frame image preparation every tracking step starts with: a 640 x 480 colour frame into
// the window image (intensity, two chromaticities and texture per pixel, window_image.h). It runs
// once per frame on the vision thread before any window is placed. Reported per pixel too.
#include <memory>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench.h"
#include "epichead/vision/window_image.h"

namespace epichead::bench {
namespace {

constexpr int kWidthPx = 640, kHeightPx = 480;

struct Prepare {
  cv::Mat frame;
  vision::WindowImage image;
};

// Smooth colour noise: edges and texture everywhere, as in a cluttered frame.
cv::Mat frame_640x480(int channels) {
  cv::Mat img(kHeightPx, kWidthPx, CV_8UC(channels));
  cv::RNG rng(5);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 2.0);
  return img;
}

Iteration prepare(int channels) {
  auto s = std::make_shared<Prepare>();
  s->frame = frame_640x480(channels);
  if (auto ok = s->image.assign(s->frame); !ok) throw std::runtime_error(ok.error());
  return [s] { (void)s->image.assign(s->frame); };
}

const Registration colour{"window_image_640x480", [] { return prepare(3); }, kWidthPx * kHeightPx};
const Registration grey{"window_image_640x480_grey", [] { return prepare(1); }, kWidthPx * kHeightPx};

}  // namespace
}  // namespace epichead::bench
