// The per-frame image preparation: a 640 x 480 frame into the window image (intensity, two
// chromaticities and texture per pixel, window_image.h). The whole frame, every tile converted
// (the cost before conversion by tiles, and the most a frame can cost), and assign() alone (the
// frame's bytes kept, which every frame pays; a tracking step then converts the tiles its
// windows read). Reported per pixel too.
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

Iteration prepare(int channels, bool every_tile) {
  auto s = std::make_shared<Prepare>();
  s->frame = frame_640x480(channels);
  if (auto ok = s->image.assign(s->frame); !ok) throw std::runtime_error(ok.error());
  s->image.prepare_all();
  return [s, every_tile] {
    (void)s->image.assign(s->frame);
    if (every_tile) s->image.prepare_all();
  };
}

const Registration colour{"window_image_640x480", [] { return prepare(3, true); }, kWidthPx * kHeightPx};
const Registration grey{"window_image_640x480_grey", [] { return prepare(1, true); }, kWidthPx * kHeightPx};
const Registration assign_only{"window_image_assign_640x480", [] { return prepare(3, false); }, kWidthPx * kHeightPx};

}  // namespace
}  // namespace epichead::bench
