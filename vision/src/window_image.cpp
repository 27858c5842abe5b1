#include "epichead/vision/window_image.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <opencv2/core.hpp>

#include "avx2_clone.h"

namespace epichead::vision {
namespace {

// Side of the square tiles the frame is converted by, px.
constexpr int kTilePx = 32;
// Floats per plane of a tile's scratch: the tile and its two-pixel margins.
constexpr std::size_t kScratchPlane = (kTilePx + 4) * (kTilePx + 4);

// Intensity and chromaticities of one pixel (b, g, r as floats) into i, cr, cg.
inline void colour_of(float b, float g, float r, float& i, float& cr, float& cg) {
  // Chromaticity offset k: (R+k)/(S+3k) tends to grey as S -> 0 instead of amplifying noise.
  constexpr float k = 8.0f;
  const float s = r + g + b;
  const float inv = 255.0f / (s + 3.0f * k);
  i = s * (1.0f / 3.0f);
  cr = (r + k) * inv;
  cg = (g + k) * inv;
}

// The runs below are also built for AVX2 (avx2_clone.h).

// n pixels of interleaved BGR (3 bytes) or BGRA (4) into the three planes.
EPICHEAD_AVX2_CLONE void colour_run_bgr(const std::uint8_t* __restrict bgr, float* __restrict intensity,
                                        float* __restrict chroma_r, float* __restrict chroma_g, int n) {
  for (int i = 0; i < n; ++i) colour_of(bgr[3 * i], bgr[3 * i + 1], bgr[3 * i + 2], intensity[i], chroma_r[i], chroma_g[i]);
}
EPICHEAD_AVX2_CLONE void colour_run_bgra(const std::uint8_t* __restrict bgra, float* __restrict intensity,
                                         float* __restrict chroma_r, float* __restrict chroma_g, int n) {
  for (int i = 0; i < n; ++i) colour_of(bgra[4 * i], bgra[4 * i + 1], bgra[4 * i + 2], intensity[i], chroma_r[i], chroma_g[i]);
}

// |dI/dx| + |dI/dy| halved, central differences, columns [a, b) with a >= 1 and b <= w - 1 (no
// clamp), from the rows above, at and below.
EPICHEAD_AVX2_CLONE void gradient_run(const float* __restrict up, const float* __restrict row, const float* __restrict down,
                                      float* __restrict out, int a, int b) {
  for (int x = a; x < b; ++x) out[x] = 0.5f * (std::fabs(row[x + 1] - row[x - 1]) + std::fabs(down[x] - up[x]));
}

// The 3x3 mean of the gradient rows r0, r1, r2 over columns [a, b) with a >= 1 and b <= w - 1,
// interleaved with the planes I, R, G into dst (4 floats per pixel).
EPICHEAD_AVX2_CLONE void texture_run(const float* __restrict r0, const float* __restrict r1, const float* __restrict r2,
                                     const float* __restrict I, const float* __restrict R, const float* __restrict G,
                                     float* __restrict dst, int a, int b) {
  for (int x = a; x < b; ++x) {
    dst[4 * x + 0] = I[x];
    dst[4 * x + 1] = R[x];
    dst[4 * x + 2] = G[x];
    dst[4 * x + 3] = (r0[x - 1] + r0[x] + r0[x + 1] + r1[x - 1] + r1[x] + r1[x + 1] + r2[x - 1] + r2[x] + r2[x + 1]) * (1.0f / 9.0f);
  }
}

// One tile's conversion: the frame's bytes and pixels, and where the tile's intermediate planes
// are (row y, column x of the image at at(y, x)).
struct Tile {
  const std::uint8_t* bytes = nullptr;
  int channels = 0, w = 0, h = 0;
  float* pixels = nullptr;
  int x0 = 0, y0 = 0, stride = 0;
  float* intensity = nullptr;
  float* chroma_r = nullptr;
  float* chroma_g = nullptr;
  float* gradient = nullptr;
  std::size_t at(int y, int x) const { return static_cast<std::size_t>(y - y0) * stride + (x - x0); }
};

// Intensity and chromaticity of row y, columns [x0, x1), into the scratch.
void colour_row(const Tile& t, int y, int x0, int x1) {
  const std::uint8_t* src = t.bytes + (static_cast<std::size_t>(y) * t.w + x0) * t.channels;
  const std::size_t at = t.at(y, x0);
  float* I = t.intensity + at;
  float* R = t.chroma_r + at;
  float* G = t.chroma_g + at;
  const int n = x1 - x0;
  switch (t.channels) {
    case 3: colour_run_bgr(src, I, R, G, n); return;
    case 4: colour_run_bgra(src, I, R, G, n); return;
    default:
      for (int i = 0; i < n; ++i) I[i] = src[i];
      std::fill_n(R, n, 85.0f);  // 255 / 3: grey
      std::fill_n(G, n, 85.0f);
  }
}

// |dI/dx| + |dI/dy| (halved) by central differences of row y, columns [x0, x1), the border
// replicated, into the scratch. The interior run has no clamps, so it vectorises; the per-pixel
// arithmetic is the same at the border and inside. Scratch columns are counted from t.x0.
void gradient_row(const Tile& t, int y, int x0, int x1) {
  const int w = t.w, h = t.h;
  const float* __restrict up = t.intensity + t.at(std::max(y - 1, 0), t.x0);
  const float* __restrict row = t.intensity + t.at(y, t.x0);
  const float* __restrict down = t.intensity + t.at(std::min(y + 1, h - 1), t.x0);
  float* __restrict out = t.gradient + t.at(y, t.x0);
  auto border = [&](int x) {
    const int xm = std::max(x - 1, 0) - t.x0, xp = std::min(x + 1, w - 1) - t.x0, c = x - t.x0;
    out[c] = 0.5f * (std::fabs(row[xp] - row[xm]) + std::fabs(down[c] - up[c]));
  };
  if (x0 == 0) border(0);
  gradient_run(up, row, down, out, std::max(x0, 1) - t.x0, std::min(x1, w - 1) - t.x0);
  if (x1 == w && w > 1) border(w - 1);
}

// The 3x3 mean of the gradient (the texture) of row y, columns [x0, x1), the border replicated,
// interleaved with the three planes into the frame-sized pixels. The nine terms are summed in the same order
// everywhere, so the interior (vectorised: the four stores form one group) and the border agree.
void interleave_row(const Tile& t, int y, int x0, int x1) {
  const int w = t.w, h = t.h;
  const float* __restrict r0 = t.gradient + t.at(std::max(y - 1, 0), t.x0);
  const float* __restrict r1 = t.gradient + t.at(y, t.x0);
  const float* __restrict r2 = t.gradient + t.at(std::min(y + 1, h - 1), t.x0);
  const float* __restrict I = t.intensity + t.at(y, t.x0);
  const float* __restrict R = t.chroma_r + t.at(y, t.x0);
  const float* __restrict G = t.chroma_g + t.at(y, t.x0);
  // dst[4 * c] is pixel t.x0 + c of row y.
  float* __restrict dst = t.pixels + 4 * (static_cast<std::size_t>(y) * w + t.x0);
  auto mean = [&](int xm, int x, int xp) {
    return (r0[xm] + r0[x] + r0[xp] + r1[xm] + r1[x] + r1[xp] + r2[xm] + r2[x] + r2[xp]) * (1.0f / 9.0f);
  };
  auto put = [&](int c, float texture) {
    dst[4 * c + 0] = I[c];
    dst[4 * c + 1] = R[c];
    dst[4 * c + 2] = G[c];
    dst[4 * c + 3] = texture;
  };
  const int o = t.x0;
  if (x0 == 0) put(0 - o, mean(0 - o, 0 - o, std::min(1, w - 1) - o));
  texture_run(r0, r1, r2, I, R, G, dst, std::max(x0, 1) - o, std::min(x1, w - 1) - o);
  if (x1 == w && w > 1) put(w - 1 - o, mean(w - 2 - o, w - 1 - o, w - 1 - o));
}

}  // namespace

std::expected<void, std::string> WindowImage::assign(const cv::Mat& frame) {
  if (frame.empty()) return std::unexpected<std::string>("empty frame");
  if (frame.depth() != CV_8U || (frame.channels() != 1 && frame.channels() != 3 && frame.channels() != 4))
    return std::unexpected<std::string>("frame must be 8-bit grey, BGR or BGRA, got type " + std::to_string(frame.type()));
  const int w = frame.cols, h = frame.rows;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (pixels_.size() < 4 * n) pixels_.resize(4 * n);
  if (scratch_.empty()) scratch_.resize(4 * kScratchPlane);
  width_px_ = w;
  height_px_ = h;
  colour_ = frame.channels() >= 3;
  tiles_x_ = (w + kTilePx - 1) / kTilePx;
  tiles_y_ = (h + kTilePx - 1) / kTilePx;
  tile_ready_.assign(static_cast<std::size_t>(tiles_x_) * tiles_y_, 0);
  tiles_prepared_ = 0;
  keep_bytes(frame);
  return {};
}

// The frame's bytes, as they are (a continuous copy: one memcpy for the usual frame).
void WindowImage::keep_bytes(const cv::Mat& frame) {
  channels_ = frame.channels();
  const std::size_t n = static_cast<std::size_t>(width_px_) * static_cast<std::size_t>(height_px_) * channels_;
  if (bytes_.size() < n) bytes_.resize(n);
  cv::Mat copy(height_px_, width_px_, frame.type(), bytes_.data());
  frame.copyTo(copy);
}

void WindowImage::prepare(const cv::Rect& region) const {
  const cv::Rect r = region & cv::Rect(0, 0, width_px_, height_px_);
  if (r.empty()) return;
  const int tx1 = (r.x + r.width - 1) / kTilePx, ty1 = (r.y + r.height - 1) / kTilePx;
  for (int ty = r.y / kTilePx; ty <= ty1; ++ty)
    for (int tx = r.x / kTilePx; tx <= tx1; ++tx)
      if (!tile_ready_[static_cast<std::size_t>(ty) * tiles_x_ + tx]) prepare_tile(tx, ty);
}

void WindowImage::prepare_span(float xa, float ya, float xb, float yb) const {
  if (!(std::isfinite(xa) && std::isfinite(ya) && std::isfinite(xb) && std::isfinite(yb))) {
    prepare_all();  // a caller that samples such a span clamps it somewhere in the image
    return;
  }
  // Clamped as a window clamps its taps (into [0, size - 1)), then the tap's pixel and its
  // right and lower neighbours.
  const float xmax = static_cast<float>(width_px_ - 1), ymax = static_cast<float>(height_px_ - 1);
  const int x0 = static_cast<int>(std::clamp(std::min(xa, xb), 0.0f, xmax));
  const int x1 = static_cast<int>(std::clamp(std::max(xa, xb), 0.0f, xmax)) + 1;
  const int y0 = static_cast<int>(std::clamp(std::min(ya, yb), 0.0f, ymax));
  const int y1 = static_cast<int>(std::clamp(std::max(ya, yb), 0.0f, ymax)) + 1;
  prepare(cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1));
}

// A tile's four channels. The texture's 3x3 mean needs the gradient one pixel around the tile,
// which needs the intensity two pixels around it: those margins are computed again for each
// tile that needs them (the same values each time), which costs less than tracking which of
// them a neighbouring tile already made. The intensity, chromaticities and gradient live only in
// a scratch the size of a tile and its margins, which stays in the L1 cache; only the
// interleaved result is written to the frame-sized buffer.
void WindowImage::prepare_tile(int tx, int ty) const {
  const int w = width_px_, h = height_px_;
  const int x0 = tx * kTilePx, x1 = std::min(w, x0 + kTilePx);
  const int y0 = ty * kTilePx, y1 = std::min(h, y0 + kTilePx);
  Tile t;
  t.bytes = bytes_.data();
  t.channels = channels_;
  t.w = w;
  t.h = h;
  t.pixels = pixels_.data();
  t.x0 = std::max(x0 - 2, 0);
  t.y0 = std::max(y0 - 2, 0);
  t.stride = std::min(x1 + 2, w) - t.x0;
  t.intensity = scratch_.data();
  t.chroma_r = t.intensity + kScratchPlane;
  t.chroma_g = t.chroma_r + kScratchPlane;
  t.gradient = t.chroma_g + kScratchPlane;
  // The tile's bytes and output rows are requested before they are needed: rows lie a frame's
  // width apart, a stride the hardware prefetchers do not follow over a tile's few lines.
  for (int y = t.y0; y < std::min(y1 + 2, h); ++y) {
    const std::uint8_t* src = bytes_.data() + (static_cast<std::size_t>(y) * w + t.x0) * channels_;
    for (int b = 0; b < t.stride * channels_; b += 64) __builtin_prefetch(src + b, 0, 3);
  }
  for (int y = y0; y < y1; ++y) {
    const float* dst = pixels_.data() + 4 * (static_cast<std::size_t>(y) * w + x0);
    for (int f = 0; f < 4 * (x1 - x0); f += 16) __builtin_prefetch(dst + f, 1, 3);
  }
  for (int y = t.y0; y < std::min(y1 + 2, h); ++y) colour_row(t, y, t.x0, std::min(x1 + 2, w));
  for (int y = std::max(y0 - 1, 0); y < std::min(y1 + 1, h); ++y) gradient_row(t, y, std::max(x0 - 1, 0), std::min(x1 + 1, w));
  for (int y = y0; y < y1; ++y) interleave_row(t, y, x0, x1);
  tile_ready_[static_cast<std::size_t>(ty) * tiles_x_ + tx] = 1;
  ++tiles_prepared_;
}

}  // namespace epichead::vision
