// Line windows: row planning, the column/ObjectSide convention, mapping back to the image,
// colour, and robustness to degenerate placement.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

// A BGR image from a per-pixel colour function (values clamped to 0..255).
template <class F>
cv::Mat make_image(int w, int h, F colour) {
  cv::Mat img(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const cv::Vec3d c = colour(x, y);
      img.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                          cv::saturate_cast<uchar>(c[2]));
    }
  return img;
}

WindowImage to_window_image(const cv::Mat& img) {
  WindowImage wi;
  REQUIRE(wi.assign(img).has_value());
  return wi;
}

}  // namespace

TEST_CASE("lines longer than 40 px are sub-sampled by powers of two to 20..40 rows", "[line_window]") {
  const WindowOptions opt;
  for (double length : {40.0, 41.0, 79.9, 80.0, 81.0, 160.5, 1000.0, 5000.0}) {
    const RowPlan plan = plan_rows(length, opt);
    INFO("length " << length);
    CHECK(plan.rows >= 20);
    CHECK(plan.rows <= 40);
    CHECK(std::exp2(std::round(std::log2(plan.step_px))) == plan.step_px);
    CHECK(plan.rows * plan.step_px <= length + 1e-9);
  }
  CHECK(plan_rows(80.0, opt).step_px == 2.0);
  CHECK(plan_rows(81.0, opt).step_px == 4.0);
}

TEST_CASE("short lines keep a 1 px step with fewer rows, degenerate ones get none", "[line_window]") {
  const WindowOptions opt;
  CHECK(plan_rows(12.7, opt).rows == 12);
  CHECK(plan_rows(12.7, opt).step_px == 1.0);
  CHECK(plan_rows(1.5, opt).rows == 2);
  CHECK(plan_rows(0.5, opt).rows == 0);
  CHECK(plan_rows(std::nan(""), opt).rows == 0);
}

TEST_CASE("the object on ObjectSide::Left of a->b lies in the window's low columns", "[line_window]") {
  // Bright on the side of the image normal (dy, -dx) of a->b, for several directions of a->b.
  const Eigen::Vector2d centre(80, 80);
  for (double angle_deg : {90.0, -90.0, 0.0, 30.0, 135.0, 200.0}) {
    const double th = angle_deg * M_PI / 180.0;
    const Eigen::Vector2d d(std::cos(th), std::sin(th));
    const Eigen::Vector2d left_normal(d.y(), -d.x());
    const cv::Mat img = make_image(160, 160, [&](int x, int y) {
      const double v = (Eigen::Vector2d(x, y) - centre).dot(left_normal) > 0 ? 220.0 : 40.0;
      return cv::Vec3d(v, v, v);
    });
    const WindowImage wi = to_window_image(img);
    LineWindow win;
    REQUIRE(win.sample(wi, centre - 30 * d, centre + 30 * d));
    const auto& g = win.geometry();
    const float* I = win.plane(CueChannel::Intensity);
    INFO("angle " << angle_deg);
    for (int r = 0; r < g.rows; ++r) {
      CHECK(I[r * g.cols + 2] > 200.0f);           // low columns: Left = object side here
      CHECK(I[r * g.cols + g.cols - 3] < 60.0f);   // high columns: Right
    }
  }
}

TEST_CASE("window samples map back to the image points they were taken at", "[line_window]") {
  // On a linear intensity ramp bilinear sampling is exact, so the sample equals the ramp at
  // to_image(x_of_col, s_of_row).
  auto ramp = [](double x, double y) { return 20.0 + 0.8 * x + 0.5 * y; };
  const cv::Mat img = make_image(200, 200, [&](int x, int y) { const double v = ramp(x, y); return cv::Vec3d(v, v, v); });
  const WindowImage wi = to_window_image(img);
  LineWindow win;
  const Eigen::Vector2d a(60.3, 50.7), b(140.2, 130.1);  // 113 px: step 4
  REQUIRE(win.sample(wi, a, b));
  const auto& g = win.geometry();
  CHECK(g.step_px == 4.0);
  CHECK(g.rows == 28);
  CHECK(g.cols == 40);
  const float* I = win.plane(CueChannel::Intensity);
  for (int r = 0; r < g.rows; r += 3)
    for (int c = 0; c < g.cols; c += 5) {
      const Eigen::Vector2d p = g.to_image(g.x_of_col(c), g.s_of_row(r));
      // The image stores rounded values: allow the rounding.
      CHECK(std::abs(I[r * g.cols + c] - ramp(p.x(), p.y())) < 0.75);
    }
  // Rows are centred on the segment and run a -> b.
  CHECK(g.s_of_row(0) > 0);
  CHECK(g.s_of_row(g.rows - 1) < g.length_px);
  CHECK(std::abs(g.s_of_row(0) - (g.length_px - g.s_of_row(g.rows - 1))) < 1e-9);
}

TEST_CASE("colour windows keep their colour and grey ones say they have none", "[line_window]") {
  const cv::Mat img = make_image(100, 100, [](int x, int) { return x < 50 ? cv::Vec3d(0, 0, 200) : cv::Vec3d(0, 200, 0); });
  const WindowImage wi = to_window_image(img);
  CHECK(wi.colour());
  LineWindow win;
  REQUIRE(win.sample(wi, {50, 20}, {50, 80}));  // down: columns run toward -x (red side high)
  const auto& g = win.geometry();
  const float* R = win.plane(CueChannel::ChromaR);
  const float* G = win.plane(CueChannel::ChromaG);
  CHECK(win.colour());
  CHECK(R[5 * g.cols + g.cols - 2] > 150.0f);  // red: chromaticity r near 1
  CHECK(G[5 * g.cols + 1] > 150.0f);           // green
  cv::Mat grey;
  cv::extractChannel(img, grey, 1);
  WindowImage wg;
  REQUIRE(wg.assign(grey).has_value());
  CHECK_FALSE(wg.colour());
}

TEST_CASE("bad frames and windows outside the image are handled without crashing", "[line_window]") {
  WindowImage wi;
  CHECK_FALSE(wi.assign(cv::Mat()).has_value());
  CHECK_FALSE(wi.assign(cv::Mat(10, 10, CV_32FC1, cv::Scalar(0))).has_value());
  REQUIRE(wi.assign(cv::Mat(30, 30, CV_8UC3, cv::Scalar(10, 20, 30))).has_value());
  LineWindow win;
  CHECK_FALSE(win.sample(wi, {5, 5}, {5.2, 5.3}));
  CHECK(win.geometry().rows == 0);
  CHECK_FALSE(win.sample(wi, {std::nan(""), 5}, {5, 25}));
  CHECK(win.sample(wi, {-500, -500}, {900, 1200}));  // far outside: border pixels repeat
  for (int k = 0; k < win.geometry().rows * win.geometry().cols; ++k)
    CHECK(std::abs(win.plane(CueChannel::Intensity)[k] - 20.0f) < 1e-3f);
}

TEST_CASE("every vector path samples exactly what the scalar bilinear tap gives", "[line_window]") {
  // The SSE and AVX2 paths interpolate 4 columns at a time; they must give, bit for bit, the
  // documented scalar tap (x lerp on both rows, then y lerp) at the float coordinates
  // x0 + c * across, so that tracking results do not depend on the instruction set.
  cv::Mat img(90, 120, CV_8UC3);
  cv::RNG rng(5);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  const int w = img.cols, h = img.rows;
  // Both the SSE path and, where the CPU has it, the AVX2 one.
  for (const bool avx2 : {false, true}) {
    WindowOptions options;
    options.allow_avx2 = avx2;
    LineWindow win(options);
    const std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> lines = {
        {{59.0, 20.0}, {59.0, 60.0}},    // vertical
        {{30.3, 40.7}, {95.2, 61.1}},    // slanted, inside
        {{3.0, 5.0}, {110.0, 88.0}},     // corners outside the image: clamped taps
        {{100.5, 10.25}, {20.75, 70.5}}, // right to left
    };
    for (const auto& [a, b] : lines) {
      // A fresh image per window, whole only after sampling: a window that read a pixel it had
      // not asked to be prepared would differ from the reference.
      const WindowImage wi = to_window_image(img);
      REQUIRE(win.sample(wi, a, b));
      wi.prepare_all();
      const float* px = wi.pixels();
      const auto& g = win.geometry();
      const float ax = static_cast<float>(g.across.x()), ay = static_cast<float>(g.across.y());
      const float xmax = static_cast<float>(w - 1) - 1e-3f, ymax = static_cast<float>(h - 1) - 1e-3f;
      int mismatches = 0;
      for (int r = 0; r < g.rows; ++r) {
        const Eigen::Vector2d p0 = g.to_image(g.x_of_col(0), g.s_of_row(r));
        const float x0 = static_cast<float>(p0.x()), y0 = static_cast<float>(p0.y());
        for (int c = 0; c < g.cols; ++c) {
          const float x = std::clamp(x0 + static_cast<float>(c) * ax, 0.0f, xmax);
          const float y = std::clamp(y0 + static_cast<float>(c) * ay, 0.0f, ymax);
          const int ix = static_cast<int>(x), iy = static_cast<int>(y);
          const float fx = x - static_cast<float>(ix), fy = y - static_cast<float>(iy);
          const float* q0 = px + 4 * (static_cast<std::size_t>(iy) * w + ix);
          const float* q1 = q0 + 4 * static_cast<std::size_t>(w);
          for (int k = 0; k < 4; ++k) {
            const float top = q0[k] + fx * (q0[4 + k] - q0[k]), bottom = q1[k] + fx * (q1[4 + k] - q1[k]);
            const float want = top + fy * (bottom - top);
            mismatches += win.plane(static_cast<CueChannel>(k))[r * g.cols + c] != want;
          }
        }
      }
      INFO("line " << a.transpose() << " -> " << b.transpose() << (avx2 ? ", AVX2 allowed" : ", SSE"));
      CHECK(mismatches == 0);
    }
  }
}
