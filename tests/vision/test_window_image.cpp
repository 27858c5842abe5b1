// WindowImage: every pixel's four channels equal their definition in window_image.h, computed
// here the plain way (per pixel, clamped neighbours), for grey, BGR and BGRA frames of sizes
// that exercise the borders (one pixel, one row, one column, odd sizes) and a full frame. The
// conversion is split into vectorised passes run tile by tile on demand; this holds them to the
// exact same numbers whichever tiles are prepared, in whatever order.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/common/allocation_counter.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

cv::Mat random_frame(int w, int h, int channels, int seed) {
  cv::Mat img(h, w, CV_8UC(channels));
  cv::RNG rng(seed);
  rng.fill(img, cv::RNG::UNIFORM, 0, 256);
  return img;
}

// The definition: intensity (R+G+B)/3, chromaticity 255 (C+k)/(R+G+B+3k) with k = 8 (grey:
// 85), texture the 3x3 mean of |dI/dx| + |dI/dy| halved, central differences, border replicated.
std::vector<float> reference(const cv::Mat& frame) {
  const int w = frame.cols, h = frame.rows, ch = frame.channels();
  std::vector<float> out(4 * static_cast<std::size_t>(w) * h), intensity(static_cast<std::size_t>(w) * h),
      gradient(intensity.size());
  constexpr float k = 8.0f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint8_t* p = frame.ptr<std::uint8_t>(y) + ch * x;
      float* o = &out[4 * (static_cast<std::size_t>(y) * w + x)];
      if (ch == 1) {
        o[0] = p[0];
        o[1] = o[2] = 85.0f;
      } else {
        const float b = p[0], g = p[1], r = p[2], s = r + g + b, inv = 255.0f / (s + 3.0f * k);
        o[0] = s * (1.0f / 3.0f);
        o[1] = (r + k) * inv;
        o[2] = (g + k) * inv;
      }
      intensity[static_cast<std::size_t>(y) * w + x] = o[0];
    }
  auto at = [&](const std::vector<float>& v, int x, int y) {
    return v[static_cast<std::size_t>(std::clamp(y, 0, h - 1)) * w + std::clamp(x, 0, w - 1)];
  };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      gradient[static_cast<std::size_t>(y) * w + x] = 0.5f * (std::fabs(at(intensity, x + 1, y) - at(intensity, x - 1, y)) +
                                                              std::fabs(at(intensity, x, y + 1) - at(intensity, x, y - 1)));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      float sum = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) sum += at(gradient, x + dx, y + dy);
      out[4 * (static_cast<std::size_t>(y) * w + x) + 3] = sum * (1.0f / 9.0f);
    }
  return out;
}

}  // namespace

TEST_CASE("every channel of every pixel equals its definition, at the borders too", "[window_image]") {
  const int sizes[][2] = {{1, 1}, {1, 7}, {9, 1}, {2, 2}, {3, 5}, {17, 13}, {640, 480}};
  for (int channels : {1, 3, 4})
    for (const auto& size : sizes) {
      const cv::Mat frame = random_frame(size[0], size[1], channels, 17 * size[0] + size[1] + channels);
      WindowImage image;
      REQUIRE(image.assign(frame));
      image.prepare_all();
      const std::vector<float> expected = reference(frame);
      INFO(size[0] << " x " << size[1] << ", " << channels << " channels");
      CHECK(image.width_px() == size[0]);
      CHECK(image.height_px() == size[1]);
      CHECK(image.colour() == (channels >= 3));
      // Exactly: the same arithmetic in the same order (the nine texture terms row by row), so
      // tracking results do not move by a bit when the passes are rearranged.
      int first_difference = -1;
      for (std::size_t i = 0; i < expected.size() && first_difference < 0; ++i)
        if (image.pixels()[i] != expected[i]) first_difference = static_cast<int>(i);
      INFO("first difference at value " << first_difference);
      CHECK(first_difference < 0);
    }
}

TEST_CASE("a frame after a larger one is converted afresh and same-sized frames allocate nothing", "[window_image]") {
  WindowImage image;
  REQUIRE(image.assign(random_frame(64, 48, 3, 1)));
  const cv::Mat small = random_frame(10, 6, 3, 2);
  REQUIRE(image.assign(small));
  image.prepare_all();
  const std::vector<float> expected = reference(small);
  for (std::size_t i = 0; i < expected.size(); i += 4) REQUIRE(image.pixels()[i] == expected[i]);
  const cv::Mat grey = random_frame(64, 48, 1, 3), colour = random_frame(64, 48, 3, 4);
  REQUIRE(image.assign(grey));
  image.prepare_all();
  REQUIRE(image.assign(colour));
  image.prepare_all();
  const auto before = epichead::common::allocation_count();
  bool ok = image.assign(grey).has_value();
  image.prepare_all();
  ok = image.assign(colour).has_value() && ok;
  image.prepare_all();
  const auto after = epichead::common::allocation_count();  // before any assertion: Catch allocates
  REQUIRE(ok);
  CHECK(after == before);
}

TEST_CASE("tiles prepared one region at a time, in any order, hold the same values as the whole frame", "[window_image]") {
  // Odd sizes: the last tile row and column are partial, and regions cross tile borders.
  for (int channels : {1, 3, 4}) {
    const cv::Mat frame = random_frame(101, 70, channels, 7 + channels);
    const std::vector<float> expected = reference(frame);
    WindowImage image;
    REQUIRE(image.assign(random_frame(101, 70, channels, 99)));  // another frame first: nothing of it may stay
    image.prepare_all();
    REQUIRE(image.assign(frame));
    CHECK(image.tiles() > 4);
    CHECK(image.tiles_prepared() == 0);
    cv::RNG rng(channels);
    std::vector<unsigned char> covered(static_cast<std::size_t>(frame.cols) * frame.rows, 0);
    for (int k = 0; k < 12; ++k) {
      const int x = rng.uniform(-10, frame.cols), y = rng.uniform(-10, frame.rows);
      const cv::Rect region(x, y, rng.uniform(1, 30), rng.uniform(1, 30));
      image.prepare(region);
      const cv::Rect in = region & cv::Rect(0, 0, frame.cols, frame.rows);
      for (int yy = in.y; yy < in.y + in.height; ++yy)
        for (int xx = in.x; xx < in.x + in.width; ++xx) covered[static_cast<std::size_t>(yy) * frame.cols + xx] = 1;
    }
    // A span's taps (and their right and lower neighbours), beyond the image at one end.
    image.prepare_span(-5.5f, 40.2f, 20.7f, 64.9f);
    for (int yy = 40; yy <= 65 && yy < frame.rows; ++yy)
      for (int xx = 0; xx <= 21; ++xx) covered[static_cast<std::size_t>(yy) * frame.cols + xx] = 1;
    INFO(channels << " channels");
    CHECK(image.tiles_prepared() < image.tiles());
    int wrong = 0;
    for (std::size_t i = 0; i < covered.size(); ++i)
      if (covered[i])
        for (int c = 0; c < 4; ++c) wrong += image.pixels()[4 * i + c] != expected[4 * i + c];
    CHECK(wrong == 0);
    image.prepare_all();
    CHECK(image.tiles_prepared() == image.tiles());
    for (std::size_t i = 0; i < expected.size(); ++i) wrong += image.pixels()[i] != expected[i];
    CHECK(wrong == 0);
  }
}

TEST_CASE("a span with a non-finite end prepares the whole frame", "[window_image]") {
  WindowImage image;
  REQUIRE(image.assign(random_frame(80, 80, 3, 5)));
  image.prepare_span(std::nanf(""), 3.0f, 10.0f, 10.0f);
  CHECK(image.tiles_prepared() == image.tiles());
}

TEST_CASE("frames of other types are refused with the type named", "[window_image]") {
  WindowImage image;
  auto r = image.assign(cv::Mat());
  REQUIRE_FALSE(r);
  CHECK(r.error() == "empty frame");
  r = image.assign(cv::Mat(4, 4, CV_16UC1, cv::Scalar(0)));
  REQUIRE_FALSE(r);
  CHECK(r.error().find("8-bit grey, BGR or BGRA") != std::string::npos);
  r = image.assign(cv::Mat(4, 4, CV_8UC2, cv::Scalar(0)));
  REQUIRE_FALSE(r);
}
