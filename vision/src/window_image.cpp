#include "epichead/vision/window_image.h"

#include <algorithm>
#include <cmath>

namespace epichead::vision {

std::expected<void, std::string> WindowImage::assign(const cv::Mat& frame) {
  if (frame.empty()) return std::unexpected<std::string>("empty frame");
  if (frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3 && frame.channels() != 4))
    return std::unexpected<std::string>("frame must be 8-bit grey, BGR or BGRA, got type " + std::to_string(frame.type()));
  const int w = frame.cols, h = frame.rows;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (pixels_.size() < 4 * n) pixels_.resize(4 * n);
  if (gradient_.size() < n) gradient_.resize(n);
  width_px_ = w;
  height_px_ = h;
  colour_ = frame.channels() >= 3;
  const int ch = frame.channels();
  // Chromaticity offset k: (R+k)/(S+3k) tends to grey as S -> 0 instead of amplifying noise.
  constexpr float k = 8.0f;
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* src = frame.ptr<std::uint8_t>(y);
    float* dst = pixels_.data() + 4 * static_cast<std::size_t>(y) * w;
    if (ch == 1) {
      for (int x = 0; x < w; ++x) {
        dst[4 * x + 0] = src[x];
        dst[4 * x + 1] = 85.0f;  // 255 / 3: grey
        dst[4 * x + 2] = 85.0f;
      }
    } else {
      for (int x = 0; x < w; ++x) {
        const float b = src[ch * x + 0], g = src[ch * x + 1], r = src[ch * x + 2];
        const float s = r + g + b;
        const float inv = 255.0f / (s + 3.0f * k);
        dst[4 * x + 0] = s * (1.0f / 3.0f);
        dst[4 * x + 1] = (r + k) * inv;
        dst[4 * x + 2] = (g + k) * inv;
      }
    }
  }
  // Texture: |dI/dx| + |dI/dy| (central differences, border replicated), then a 3x3 mean.
  auto I = [&](int x, int y) { return pixels_[4 * (static_cast<std::size_t>(y) * w + x)]; };
  for (int y = 0; y < h; ++y) {
    const int ym = std::max(y - 1, 0), yp = std::min(y + 1, h - 1);
    for (int x = 0; x < w; ++x) {
      const int xm = std::max(x - 1, 0), xp = std::min(x + 1, w - 1);
      gradient_[static_cast<std::size_t>(y) * w + x] =
          0.5f * (std::fabs(I(xp, y) - I(xm, y)) + std::fabs(I(x, yp) - I(x, ym)));
    }
  }
  for (int y = 0; y < h; ++y) {
    const int ym = std::max(y - 1, 0), yp = std::min(y + 1, h - 1);
    const float* r0 = gradient_.data() + static_cast<std::size_t>(ym) * w;
    const float* r1 = gradient_.data() + static_cast<std::size_t>(y) * w;
    const float* r2 = gradient_.data() + static_cast<std::size_t>(yp) * w;
    float* dst = pixels_.data() + 4 * static_cast<std::size_t>(y) * w;
    for (int x = 0; x < w; ++x) {
      const int xm = std::max(x - 1, 0), xp = std::min(x + 1, w - 1);
      dst[4 * x + 3] = (r0[xm] + r0[x] + r0[xp] + r1[xm] + r1[x] + r1[xp] + r2[xm] + r2[x] + r2[xp]) * (1.0f / 9.0f);
    }
  }
  return {};
}

}  // namespace epichead::vision
