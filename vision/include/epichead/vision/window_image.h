#pragma once
// A camera frame converted once per frame into the layout that line windows sample from:
// per pixel four floats (intensity, chromaticity r, chromaticity g, texture), interleaved so
// that one bilinear tap reads all cue channels at once. The per-window hot path never touches
// cv::Mat; this is the image boundary.
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
  // Converts an 8-bit frame: 1 channel (grey), 3 (BGR) or 4 (BGRA). Buffers grow to the frame
  // size once and are reused, so same-sized frames allocate nothing. Other types are an error.
  std::expected<void, std::string> assign(const cv::Mat& frame);

  int width_px() const { return width_px_; }
  int height_px() const { return height_px_; }
  // True for colour frames; grey frames carry constant chromaticity and the colour cue is off.
  bool colour() const { return colour_; }
  // Row-major, 4 floats per pixel: intensity 0..255 = (R+G+B)/3; chromaticity r, g scaled to
  // 0..255 = 255 (R+k)/(R+G+B+3k) with k = 8 grey levels (keeps dark pixels from amplifying
  // noise); texture = 3x3 mean of |dI/dx| + |dI/dy| (central differences), grey levels per px.
  const float* pixels() const { return pixels_.data(); }

 private:
  void convert_pixels(const cv::Mat& frame);
  void texture_gradient();
  void interleave_with_texture();

  int width_px_ = 0, height_px_ = 0;
  bool colour_ = false;
  std::vector<float> pixels_;
  // Scratch, one plane per channel before they are interleaved (contiguous loops vectorise).
  std::vector<std::uint8_t> bgr_;  // the frame's B, G and R planes
  std::vector<float> intensity_, chroma_r_, chroma_g_;
  std::vector<float> gradient_;   // scratch: |dI/dx| + |dI/dy| before the 3x3 mean
};

}  // namespace epichead::vision
