#include "epichead/vision/window_image.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/core.hpp>

namespace epichead::vision {
namespace {

// Intensity and chromaticities of n pixels from byte planes. A free function with __restrict
// arguments: bytes may alias anything, and as a member loop the compiler kept it scalar.
void colour_planes(const std::uint8_t* __restrict blue, const std::uint8_t* __restrict green,
                   const std::uint8_t* __restrict red, float* __restrict intensity, float* __restrict chroma_r,
                   float* __restrict chroma_g, std::size_t n) {
  // Chromaticity offset k: (R+k)/(S+3k) tends to grey as S -> 0 instead of amplifying noise.
  constexpr float k = 8.0f;
  for (std::size_t i = 0; i < n; ++i) {
    const float b = blue[i], g = green[i], r = red[i];
    const float s = r + g + b;
    const float inv = 255.0f / (s + 3.0f * k);
    intensity[i] = s * (1.0f / 3.0f);
    chroma_r[i] = (r + k) * inv;
    chroma_g[i] = (g + k) * inv;
  }
}

}  // namespace

std::expected<void, std::string> WindowImage::assign(const cv::Mat& frame) {
  if (frame.empty()) return std::unexpected<std::string>("empty frame");
  if (frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3 && frame.channels() != 4))
    return std::unexpected<std::string>("frame must be 8-bit grey, BGR or BGRA, got type " + std::to_string(frame.type()));
  const int w = frame.cols, h = frame.rows;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (pixels_.size() < 4 * n) pixels_.resize(4 * n);
  if (intensity_.size() < n) {
    intensity_.resize(n);
    chroma_r_.resize(n);
    chroma_g_.resize(n);
  }
  if (gradient_.size() < n) gradient_.resize(n);
  width_px_ = w;
  height_px_ = h;
  colour_ = frame.channels() >= 3;
  convert_pixels(frame);
  texture_gradient();
  interleave_with_texture();
  return {};
}

// Intensity and chromaticity as planes (contiguous, so the arithmetic vectorises; the frame's
// channels are first split into byte planes by OpenCV, which allocates nothing once sized).
void WindowImage::convert_pixels(const cv::Mat& frame) {
  const int w = width_px_, h = height_px_;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (frame.channels() == 1) {
    for (int y = 0; y < h; ++y) {
      const std::uint8_t* src = frame.ptr<std::uint8_t>(y);
      float* plane = intensity_.data() + static_cast<std::size_t>(y) * w;
      for (int x = 0; x < w; ++x) plane[x] = src[x];
    }
    std::fill(chroma_r_.begin(), chroma_r_.begin() + static_cast<std::ptrdiff_t>(n), 85.0f);  // 255 / 3: grey
    std::fill(chroma_g_.begin(), chroma_g_.begin() + static_cast<std::ptrdiff_t>(n), 85.0f);
    return;
  }
  if (bgr_.size() < 3 * n) bgr_.resize(3 * n);
  cv::Mat planes[3] = {cv::Mat(h, w, CV_8UC1, bgr_.data()), cv::Mat(h, w, CV_8UC1, bgr_.data() + n),
                       cv::Mat(h, w, CV_8UC1, bgr_.data() + 2 * n)};
  constexpr int kFromTo[] = {0, 0, 1, 1, 2, 2};  // B, G, R (a fourth channel, alpha, is left out)
  cv::mixChannels(&frame, 1, planes, 3, kFromTo, 3);
  colour_planes(bgr_.data(), bgr_.data() + n, bgr_.data() + 2 * n, intensity_.data(), chroma_r_.data(), chroma_g_.data(), n);
}

// |dI/dx| + |dI/dy| by central differences, the border replicated. The interior loop has no
// clamps, so it vectorises; the per-pixel arithmetic is the same at the border and inside.
void WindowImage::texture_gradient() {
  const int w = width_px_, h = height_px_;
  const float* I = intensity_.data();
  auto at = [&](int x, int y) { return I[static_cast<std::size_t>(y) * w + x]; };
  for (int y = 0; y < h; ++y) {
    const float* __restrict up = I + static_cast<std::size_t>(std::max(y - 1, 0)) * w;
    const float* __restrict row = I + static_cast<std::size_t>(y) * w;
    const float* __restrict down = I + static_cast<std::size_t>(std::min(y + 1, h - 1)) * w;
    float* __restrict out = gradient_.data() + static_cast<std::size_t>(y) * w;
    auto border = [&](int x) {
      const int xm = std::max(x - 1, 0), xp = std::min(x + 1, w - 1);
      out[x] = 0.5f * (std::fabs(at(xp, y) - at(xm, y)) + std::fabs(down[x] - up[x]));
    };
    border(0);
    for (int x = 1; x < w - 1; ++x) out[x] = 0.5f * (std::fabs(row[x + 1] - row[x - 1]) + std::fabs(down[x] - up[x]));
    if (w > 1) border(w - 1);
  }
}

// The 3x3 mean of the gradient (the texture), the border replicated, interleaved with the three
// planes into pixels_. The nine terms are summed in the same order everywhere, so the interior
// (vectorised: the four stores form one group) and the border agree.
void WindowImage::interleave_with_texture() {
  const int w = width_px_, h = height_px_;
  for (int y = 0; y < h; ++y) {
    const std::size_t row = static_cast<std::size_t>(y) * w;
    const float* __restrict r0 = gradient_.data() + static_cast<std::size_t>(std::max(y - 1, 0)) * w;
    const float* __restrict r1 = gradient_.data() + row;
    const float* __restrict r2 = gradient_.data() + static_cast<std::size_t>(std::min(y + 1, h - 1)) * w;
    const float* __restrict I = intensity_.data() + row;
    const float* __restrict R = chroma_r_.data() + row;
    const float* __restrict G = chroma_g_.data() + row;
    float* __restrict dst = pixels_.data() + 4 * row;
    auto mean = [&](int xm, int x, int xp) {
      return (r0[xm] + r0[x] + r0[xp] + r1[xm] + r1[x] + r1[xp] + r2[xm] + r2[x] + r2[xp]) * (1.0f / 9.0f);
    };
    auto put = [&](int x, float texture) {
      dst[4 * x + 0] = I[x];
      dst[4 * x + 1] = R[x];
      dst[4 * x + 2] = G[x];
      dst[4 * x + 3] = texture;
    };
    put(0, mean(0, 0, std::min(1, w - 1)));
    for (int x = 1; x < w - 1; ++x) put(x, mean(x - 1, x, x + 1));
    if (w > 1) put(w - 1, mean(w - 2, w - 1, w - 1));
  }
}

}  // namespace epichead::vision
