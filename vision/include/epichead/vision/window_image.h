#pragma once
// A camera frame converted into the layout that line windows sample from: per pixel four floats
// (intensity, chromaticity r, chromaticity g, texture), interleaved so that one bilinear tap
// reads all cue channels at once. The per-window hot path never touches cv::Mat; this is the
// image boundary.
//
// The conversion is lazy, by tiles: assign() keeps the frame's bytes, and a reader asks for the
// pixels it will read (prepare, prepare_span) before reading them. The windows of a tracking
// step cover a small part of the frame, and a whole frame's conversion cost about twice the
// step itself (docs/performance.md). A prepared pixel has the same value whichever tiles were
// prepared before it, and in whatever order.
//
// One thread at a time: preparing writes the image's buffers from const readers (the image is
// a per-frame scratch of one tracker, which samples it from const references).
#include <cstdint>
#include <expected>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace epichead::vision {

// Channel order of a WindowImage pixel (and of the planes of a LineWindow).
enum class CueChannel { Intensity = 0, ChromaR = 1, ChromaG = 2, Texture = 3 };
inline constexpr int kCueChannels = 4;

class WindowImage {
 public:
  // Takes an 8-bit frame: 1 channel (grey), 3 (BGR) or 4 (BGRA). Its bytes are copied (the
  // caller may reuse the frame); no pixel is converted yet. Buffers grow to the frame size once
  // and are reused, so same-sized frames allocate nothing. Other types are an error.
  std::expected<void, std::string> assign(const cv::Mat& frame);

  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  // True for colour frames; grey frames carry constant chromaticity and the colour cue is off.
  bool colour() const { return colour_; }
  // Row-major, 4 floats per pixel: intensity 0..255 = (R+G+B)/3; chromaticity r, g scaled to
  // 0..255 = 255 (R+k)/(R+G+B+3k) with k = 8 grey levels (keeps dark pixels from amplifying
  // noise); texture = 3x3 mean of |dI/dx| + |dI/dy| (central differences), grey levels per px.
  // Valid where prepared: read only pixels made ready by prepare() or prepare_span() since the
  // last assign().
  const float* pixels() const { return pixels_.data(); }

  // Makes the pixels of `region` (clipped to the image) ready. Cheap when they already are.
  void prepare(const cv::Rect& region) const;
  // Makes ready every pixel a bilinear tap reads anywhere on the segment a-b (pixel
  // coordinates; each tap reads its pixel and the next one right and down), with points beyond
  // the image clamped to its border as the windows clamp them.
  void prepare_span(float xa, float ya, float xb, float yb) const;
  void prepare_all() const { prepare(cv::Rect(0, 0, width_px_, height_px_)); }
  // Tiles converted since the last assign(), and the frame's tile count.
  int tiles_prepared() const { return tiles_prepared_; }
  int tiles() const { return tiles_x_ * tiles_y_; }

 private:
  void keep_bytes(const cv::Mat& frame);
  void prepare_tile(int tx, int ty) const;

  int width_px_ = 0, height_px_ = 0;
  bool colour_ = false;
  int channels_ = 0;
  int tiles_x_ = 0, tiles_y_ = 0;
  std::vector<std::uint8_t> bytes_;  // the frame's bytes, rows back to back
  mutable std::vector<std::uint8_t> tile_ready_;  // per tile, row-major
  mutable int tiles_prepared_ = 0;
  mutable std::vector<float> pixels_;
  // A tile's intensity, chromaticities and |dI/dx| + |dI/dy| (before the 3x3 mean), one plane
  // each with the tile's margins, before they are interleaved (contiguous loops vectorise).
  mutable std::vector<float> scratch_;
};

}  // namespace epichead::vision
