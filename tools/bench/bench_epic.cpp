// EPIC window benchmarks: one 40 x 40 window (a 40 px line) with three cues (colour frame):
// sampling + edgels + interval cues + likelihoods + RANSAC candidates + reference update.
// The harness reports ns per window pixel (kWindowPixels items per iteration).
#include <memory>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "bench/bench.h"
#include "epichead/vision/cues.h"
#include "epichead/vision/edgels.h"
#include "epichead/vision/epic.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

namespace epichead::bench {
namespace {

using namespace epichead::vision;

// A textured object (x > 60) next to a background with a strong clutter edge, noisy: the
// window holds the object edge, clutter, texture edgels and noise, as on a real frame.
cv::Mat scene() {
  cv::Mat img(120, 120, CV_8UC3);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      cv::Vec3b c;
      if (x > 60) c = ((x / 5 + y / 7) % 3 == 0) ? cv::Vec3b(40, 80, 120) : cv::Vec3b(60, 100, 140);
      else if (x > 50) c = cv::Vec3b(150, 150, 150);
      else c = cv::Vec3b(250, 250, 250);
      img.at<cv::Vec3b>(y, x) = c;
    }
  cv::GaussianBlur(img, img, cv::Size(0, 0), 1.0);
  cv::Mat noise(img.size(), CV_8SC3);
  cv::RNG rng(3);
  rng.fill(noise, cv::RNG::NORMAL, 0, 2);
  cv::add(img, noise, img, cv::noArray(), CV_8UC3);
  return img;
}

constexpr int kWindowPixels = 40 * 40;

struct State {
  WindowImage image;
  LineWindow window;
  EpicDetector detector;
  EpicResult result;
  FeatureReferences refs;
  Eigen::Vector2d a{59.0, 40.0}, b{59.0, 80.0};  // 40 px: 40 rows of 40 columns
  EpicMode mode;
  explicit State(EpicMode m) : mode(m) {
    (void)image.assign(scene());
    result.reserve({}, EpicOptions{}.ransac);
    window.sample(image, a, b);
    detector.init_references(window, ObjectSide::Left, refs);
  }
  void run() {
    window.sample(image, a, b);
    // With look-through, as LineTracker runs an edge without a close parallel one (this one).
    detector.detect(window, ObjectSide::Left, refs, mode, result, true);
    if (mode != EpicMode::Gradient && result.found())
      detector.update_references(result, result.candidates.front(), ObjectSide::Left, refs);
  }
};

const Registration epic_window{"epic_window", [] {
  auto s = std::make_shared<State>(EpicMode::Epic);
  return [s] { s->run(); };
}, kWindowPixels};

// The sampling step alone (the bilinear warp into the four cue planes), to split epic_window.
const Registration epic_window_sample{"epic_window_sample", [] {
  auto s = std::make_shared<State>(EpicMode::Epic);
  return [s] { s->window.sample(s->image, s->a, s->b); };
}, kWindowPixels};
// Sampling + edgels, and sampling + edgels + the interval cues: the steps of epic_window in turn.
const Registration epic_window_edgels{"epic_window_edgels", [] {
  auto s = std::make_shared<State>(EpicMode::Epic);
  return [s] {
    s->window.sample(s->image, s->a, s->b);
    find_edgels(s->window, EdgelOptions{}, s->result.edgels);
  };
}, kWindowPixels};
const Registration epic_window_cues{"epic_window_cues", [] {
  struct Cues {
    State state{EpicMode::Epic};
    CueHistograms histograms{CueOptions{}};
    std::vector<IntervalCues> intervals;
  };
  auto s = std::make_shared<Cues>();
  s->intervals.reserve(4096);
  return [s] {
    State& st = s->state;
    st.window.sample(st.image, st.a, st.b);
    find_edgels(st.window, EdgelOptions{}, st.result.edgels);
    s->histograms.prepare(st.window);
    s->histograms.intervals(st.window, st.result.edgels, s->intervals, true, false);  // ObjectSide::Left
  };
}, kWindowPixels};
const Registration epic_window_single{"epic_window_single", [] {
  auto s = std::make_shared<State>(EpicMode::EpicSingle);
  return [s] { s->run(); };
}, kWindowPixels};
const Registration epic_window_gradient{"epic_window_gradient", [] {
  auto s = std::make_shared<State>(EpicMode::Gradient);
  return [s] { s->run(); };
}, kWindowPixels};

}  // namespace
}  // namespace epichead::bench
