// Interval cues: the vector paths (one register up to 16 pixels, two up to 32) and the histogram
// loop must all give what the plain definition gives: per cue the mode of the interval's
// histogram (the first bin to reach the top count wins a tie), refined to the mean of the
// samples in the modal bin summed in pixel order.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "epichead/vision/cues.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

// The bins of CueHistograms::prepare: value * bins / range, clamped, truncated.
int bin_of(float v, float scale, int bins) {
  float x = v * scale;
  x = x > 0.0f ? x : 0.0f;
  x = x < bins - 0.5f ? x : bins - 0.5f;
  return static_cast<int>(x);
}

IntervalCues reference_interval(const LineWindow& window, const CueOptions& o, int row, int c0, int c1) {
  const int cols = window.geometry().cols;
  const float* I = window.plane(CueChannel::Intensity) + row * cols;
  const float* R = window.plane(CueChannel::ChromaR) + row * cols;
  const float* G = window.plane(CueChannel::ChromaG) + row * cols;
  const float* T = window.plane(CueChannel::Texture) + row * cols;
  std::vector<std::array<int, 3>> bins;
  for (int c = c0; c < c1; ++c)
    bins.push_back({bin_of(I[c], o.intensity_bins / 256.0f, o.intensity_bins),
                    bin_of(R[c], o.chroma_bins / 256.0f, o.chroma_bins) * o.chroma_bins +
                        bin_of(G[c], o.chroma_bins / 256.0f, o.chroma_bins),
                    bin_of(T[c], o.texture_bins / o.texture_range, o.texture_bins)});
  IntervalCues out;
  std::array<int, 3> mode{}, top{};
  for (int k = 0; k < 3; ++k) {
    std::vector<int> count(256 * 256, 0);
    for (const auto& b : bins)
      if (++count[b[k]] > top[k]) { top[k] = count[b[k]]; mode[k] = b[k]; }
  }
  std::array<float, 4> sum{};
  for (int c = c0; c < c1; ++c) {
    const auto& b = bins[c - c0];
    sum[0] += b[0] == mode[0] ? I[c] : 0.0f;
    sum[1] += b[1] == mode[1] ? R[c] : 0.0f;
    sum[2] += b[1] == mode[1] ? G[c] : 0.0f;
    sum[3] += b[2] == mode[2] ? T[c] : 0.0f;
  }
  out.value = {sum[0] / top[0], sum[1] / top[1], sum[2] / top[1], sum[3] / top[2]};
  out.valid = true;
  return out;
}

}  // namespace

TEST_CASE("interval cues equal the plain histogram mode for every interval length", "[cues]") {
  // Few distinct colours, so that bins tie often and the tie rule is exercised.
  cv::Mat img(80, 80, CV_8UC3);
  cv::RNG rng(11);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const int k = rng.uniform(0, 4);
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<uchar>(40 + 50 * k), static_cast<uchar>(200 - 30 * k),
                                          static_cast<uchar>(rng.uniform(60, 90)));
    }
  WindowImage image;
  REQUIRE(image.assign(img).has_value());
  for (const CueOptions& options : {CueOptions{}, CueOptions{8, 4, 8, 32.0f}, CueOptions{32, 32, 32, 64.0f}}) {
    LineWindow window;  // 40 columns: lengths 1..40 reach all three paths
    REQUIRE(window.sample(image, Eigen::Vector2d(37.3, 12.6), Eigen::Vector2d(44.1, 60.2)));
    CueHistograms histograms(options);
    histograms.prepare(window);
    const auto& g = window.geometry();
    int checked = 0, mismatches = 0;
    for (int r = 0; r < g.rows; r += 3)
      for (int c0 = 0; c0 < g.cols; c0 += 5)
        for (int c1 = c0 + 1; c1 <= g.cols; ++c1) {
          const IntervalCues got = histograms.interval(window, r, c0, c1);
          const IntervalCues want = reference_interval(window, options, r, c0, c1);
          ++checked;
          mismatches += !(got.valid && got.value == want.value);
        }
    INFO("checked " << checked);
    CHECK(mismatches == 0);
  }
}

TEST_CASE("an empty or out-of-window interval is invalid", "[cues]") {
  WindowImage image;
  REQUIRE(image.assign(cv::Mat(60, 60, CV_8UC3, cv::Scalar(10, 20, 30))).has_value());
  LineWindow window;
  REQUIRE(window.sample(image, Eigen::Vector2d(30, 10), Eigen::Vector2d(30, 50)));
  CueHistograms histograms;
  histograms.prepare(window);
  CHECK_FALSE(histograms.interval(window, 0, 5, 5).valid);
  CHECK_FALSE(histograms.interval(window, -1, 0, 10).valid);
  CHECK_FALSE(histograms.interval(window, window.geometry().rows, 0, 10).valid);
  CHECK(histograms.interval(window, 0, 0, 40).valid);
}
