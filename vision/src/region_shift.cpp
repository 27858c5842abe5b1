#include "epichead/vision/region_shift.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdint>
#include <vector>

#include <opencv2/core/hal/hal.hpp>
#include <opencv2/imgproc.hpp>

namespace epichead::vision {
namespace {
// The region is correlated at a fixed kSidePx x kSidePx (each axis scaled on its own): one size
// means one DFT plan and buffers made once, and a shift needs a pixel or two of precision, not
// the frame's. A region under kMinSidePx a side is too small to correlate.
constexpr int kSidePx = 64;
constexpr int kMinSidePx = 32;

// One source row's grey values added to `sums` (the region's width): B, G, R weighted as BT.601,
// with the channel count fixed so that the compiler vectorises the loop.
template <int Channels>
void add_grey_row(const std::uint8_t* p, int width, float* sums) {
  if constexpr (Channels == 1) {
    for (int x = 0; x < width; ++x) sums[x] += p[x];
  } else {
    for (int x = 0; x < width; ++x)
      sums[x] += 0.114f * p[x * Channels] + 0.587f * p[x * Channels + 1] + 0.299f * p[x * Channels + 2];
  }
}

// The mean grey of each of the kSidePx x kSidePx boxes that tile the region, times `window`,
// into `out`: what cv::resize's INTER_AREA and a grey conversion give, up to rounding, without
// the tables cv::resize allocates on every call. `columns` holds one row of grey sums across the
// region (the frame's width).
void shrink_grey(const cv::Mat& frame, const cv::Rect& region, const cv::Mat& window, std::vector<float>& columns,
                 cv::Mat& out) {
  std::array<int, kSidePx + 1> xs, ys;
  for (int i = 0; i <= kSidePx; ++i) {
    xs[static_cast<std::size_t>(i)] = i * region.width / kSidePx;
    ys[static_cast<std::size_t>(i)] = region.y + i * region.height / kSidePx;
  }
  const int channels = frame.channels(), width = region.width;
  float* sums = columns.data();
  for (int j = 0; j < kSidePx; ++j) {
    // A region narrower than kSidePx repeats its pixels (a box at least one pixel wide).
    const int y0 = ys[static_cast<std::size_t>(j)], y1 = std::max(ys[static_cast<std::size_t>(j) + 1], y0 + 1);
    std::fill(sums, sums + width, 0.0f);
    for (int y = y0; y < y1; ++y) {
      const std::uint8_t* p = frame.ptr<std::uint8_t>(y) + static_cast<std::ptrdiff_t>(region.x) * channels;
      if (channels == 3) add_grey_row<3>(p, width, sums);
      else if (channels == 4) add_grey_row<4>(p, width, sums);
      else add_grey_row<1>(p, width, sums);
    }
    float* o = out.ptr<float>(j);
    const float* w = window.ptr<float>(j);
    for (int i = 0; i < kSidePx; ++i) {
      const int x0 = xs[static_cast<std::size_t>(i)], x1 = std::max(xs[static_cast<std::size_t>(i) + 1], x0 + 1);
      float sum = 0;
      for (int x = x0; x < x1; ++x) sum += sums[x];
      o[i] = w[i] * sum / static_cast<float>((x1 - x0) * (y1 - y0));
    }
  }
}

// Sub-pixel place of the peak along one axis from its neighbours (a parabola through three).
double parabola_offset(float left, float centre, float right) {
  const double d = static_cast<double>(left) - 2.0 * centre + right;
  if (!(d < 0)) return 0;
  const double o = 0.5 * (static_cast<double>(left) - right) / d;
  return std::abs(o) <= 0.5 ? o : 0.0;
}
}  // namespace

RegionShiftEstimator::RegionShiftEstimator()
    : a_(kSidePx, kSidePx, CV_32F),
      b_(kSidePx, kSidePx, CV_32F),
      spectrum_a_(kSidePx, kSidePx, CV_32FC2),
      spectrum_b_(kSidePx, kSidePx, CV_32FC2),
      cross_(kSidePx, kSidePx, CV_32FC2),
      surface_(kSidePx, kSidePx, CV_32F),
      // OpenCV's DFT planned once for the one size: cv::dft plans on every call (seven
      // allocations each), its HAL object reuses the plan and allocates nothing.
      forward_(cv::hal::DFT2D::create(kSidePx, kSidePx, CV_32F, 1, 2, cv::DFT_COMPLEX_OUTPUT)),
      inverse_(cv::hal::DFT2D::create(kSidePx, kSidePx, CV_32F, 2, 1, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT)) {
  cv::createHanningWindow(window_, cv::Size(kSidePx, kSidePx), CV_32F);
}

std::optional<RegionShift> RegionShiftEstimator::push(const cv::Mat& frame, const cv::Rect& region_px) {
  const int channels = frame.channels();
  if (frame.empty() || frame.depth() != CV_8U || (channels != 1 && channels != 3 && channels != 4)) return std::nullopt;
  std::optional<RegionShift> out;
  const bool comparable = have_previous_ && previous_.size() == frame.size() && previous_.type() == frame.type();
  const cv::Rect region = region_px & cv::Rect(0, 0, frame.cols, frame.rows);
  // Only the region is converted and correlated: a frame's worth of work would cost several
  // tracking steps. OpenCV's phaseCorrelate does the same sums but took 1-2 ms here.
  if (comparable && region.width >= kMinSidePx && region.height >= kMinSidePx) {
    shrink_grey(previous_, region, window_, columns_, a_);
    shrink_grey(frame, region, window_, columns_, b_);
    forward_->apply(a_.data, a_.step, spectrum_a_.data, spectrum_a_.step);
    forward_->apply(b_.data, b_.step, spectrum_b_.data, spectrum_b_.step);
    // The normalised cross-power spectrum B conj(A) / |B conj(A)|: its inverse is a peak at the
    // shift of b against a (where a's content went), as high as the share of the region that
    // moved as one.
    cv::mulSpectrums(spectrum_b_, spectrum_a_, cross_, 0, true);
    for (int y = 0; y < cross_.rows; ++y) {
      auto* c = cross_.ptr<std::complex<float>>(y);
      for (int x = 0; x < cross_.cols; ++x) {
        const float m = std::abs(c[x]);
        c[x] = m > 1e-12f ? c[x] / m : std::complex<float>(0, 0);
      }
    }
    inverse_->apply(cross_.data, cross_.step, surface_.data, surface_.step);
    cv::Point peak;
    double peak_value = 0;
    cv::minMaxLoc(surface_, nullptr, &peak_value, nullptr, &peak);
    const int w = surface_.cols, h = surface_.rows;
    const auto at = [&](int x, int y) { return surface_.at<float>((y + h) % h, (x + w) % w); };
    double dx = peak.x + parabola_offset(at(peak.x - 1, peak.y), at(peak.x, peak.y), at(peak.x + 1, peak.y));
    double dy = peak.y + parabola_offset(at(peak.x, peak.y - 1), at(peak.x, peak.y), at(peak.x, peak.y + 1));
    if (dx > w / 2.0) dx -= w;  // the surface wraps around: the far half is a negative shift
    if (dy > h / 2.0) dy -= h;
    const double scale_x = static_cast<double>(region.width) / w, scale_y = static_cast<double>(region.height) / h;
    out = RegionShift{Eigen::Vector2d(dx * scale_x, dy * scale_y), peak_value};
  }
  frame.copyTo(previous_);  // into the same buffer each frame of one size
  if (static_cast<int>(columns_.size()) < frame.cols) columns_.resize(static_cast<std::size_t>(frame.cols));
  have_previous_ = true;
  return out;
}

}  // namespace epichead::vision
