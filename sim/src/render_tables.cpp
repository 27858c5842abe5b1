// The renderer's tables, built once: gamma decode and encode, the Gaussian quantiles of the
// noise, the sub-pixel sample patterns and the textures' mip pyramids.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <opencv2/imgproc.hpp>

#include "renderer_impl.h"

namespace epichead::sim {
namespace {

using render::kDecodeFine;
using render::kEncodeSteps;
using render::kFixOne;

// A sample pattern for T samples: distinct x and y offsets (an axis-aligned edge gets T + 1 grey
// levels) spread over the pixel. Rank-1 lattice (s, s*p mod T); small T brute-force the best
// permutation (the rotated-grid pattern for T = 4).
std::vector<Eigen::Vector2i> make_pattern(int T) {
  std::vector<int> best_perm(static_cast<std::size_t>(T));
  for (int i = 0; i < T; ++i) best_perm[static_cast<std::size_t>(i)] = i;
  auto min_dist = [&](const std::vector<int>& perm) {
    double best = 1e9;
    for (int i = 0; i < T; ++i)
      for (int j = i + 1; j < T; ++j) {
        double dx = std::abs(i - j), dy = std::abs(perm[static_cast<std::size_t>(i)] - perm[static_cast<std::size_t>(j)]);
        dx = std::min(dx, T - dx);
        dy = std::min(dy, T - dy);
        best = std::min(best, dx * dx + dy * dy);
      }
    return best;
  };
  double best = -1;
  if (T <= 8) {
    std::vector<int> perm = best_perm;
    do {
      const double d = min_dist(perm);
      if (d > best) { best = d; best_perm = perm; }
    } while (std::next_permutation(perm.begin(), perm.end()));
  } else {
    for (int p = 1; p < T; ++p) {
      if (std::gcd(p, T) != 1) continue;
      std::vector<int> perm(static_cast<std::size_t>(T));
      for (int s = 0; s < T; ++s) perm[static_cast<std::size_t>(s)] = (s * p) % T;
      const double d = min_dist(perm);
      if (d > best) { best = d; best_perm = perm; }
    }
  }
  std::vector<Eigen::Vector2i> out;
  for (int s = 0; s < T; ++s) {
    // Offsets from the pixel centre in 1/256 px, in (-128, 128).
    const auto off = [&](int i) {
      return static_cast<int>(std::lround(((i + 0.5) / T - 0.5) * static_cast<double>(kFixOne)));
    };
    out.emplace_back(off(s), off(best_perm[static_cast<std::size_t>(s)]));
  }
  return out;
}

double inverse_normal(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  if (p < 0.02425) {
    const double q = std::sqrt(-2 * std::log(p));
    return (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
           ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
  }
  if (p > 1 - 0.02425) return -inverse_normal(1 - p);
  const double q = p - 0.5, r = q * q;
  return (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
         (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
}

}  // namespace

void Renderer::Impl::setup_tables() {
  const double g = opt.gamma > 0 ? opt.gamma : 1.0;
  for (int i = 0; i < 256; ++i) decode_lut[i] = static_cast<float>(std::pow(i / 255.0, g));
  for (int i = 0; i <= 255 * kDecodeFine + 1; ++i)
    decode_fine[i] = static_cast<float>(std::pow(std::min(1.0, i / (255.0 * kDecodeFine)), g));
  encode_lut.resize(kEncodeSteps + 1);
  for (int i = 0; i <= kEncodeSteps; ++i)
    encode_lut[static_cast<std::size_t>(i)] = static_cast<float>(255.0 * std::pow(static_cast<double>(i) / kEncodeSteps, 1.0 / g));
  gauss_table.resize(65536);
  // Inverse normal CDF at bin centres (Acklam's rational approximation refined by one Newton
  // step on erfc), so a 16-bit uniform draw gives a Gaussian value.
  for (int i = 0; i < 65536; ++i) {
    const double p = (i + 0.5) / 65536.0;
    double x = inverse_normal(p);
    const double e = 0.5 * std::erfc(-x / std::numbers::sqrt2) - p;
    x -= e * std::sqrt(2 * std::numbers::pi) * std::exp(x * x / 2);
    gauss_table[static_cast<std::size_t>(i)] = static_cast<float>(x);
  }
}

void Renderer::Impl::setup_textures() {
  tex_mips.resize(scene.textures.size());
  for (const auto& mat : scene.materials) {
    if (mat.texture < 0) continue;
    auto& mips = tex_mips[static_cast<std::size_t>(mat.texture)];
    if (!mips.empty()) continue;
    const cv::Mat& t8 = scene.textures[static_cast<std::size_t>(mat.texture)];
    cv::Mat bgra;
    cv::cvtColor(t8, bgra, cv::COLOR_BGR2BGRA);
    mips.push_back({bgra, 1.f, 1.f, 1.f / static_cast<float>(bgra.cols), 1.f / static_cast<float>(bgra.rows)});
    while (mips.back().image.cols >= 8 && mips.back().image.rows >= 8 && mips.size() < 12) {
      cv::Mat half;
      cv::resize(mips.back().image, half, cv::Size(mips.back().image.cols / 2, mips.back().image.rows / 2), 0, 0,
                 cv::INTER_AREA);
      mips.push_back({half, static_cast<float>(half.cols) / static_cast<float>(t8.cols),
                      static_cast<float>(half.rows) / static_cast<float>(t8.rows), 1.f / static_cast<float>(half.cols),
                      1.f / static_cast<float>(half.rows)});
    }
  }
}

const std::vector<Eigen::Vector2i>& Renderer::Impl::pattern(int total) {
  auto& p = patterns[static_cast<std::size_t>(total)];
  if (p.empty()) p = make_pattern(total);
  return p;
}

}  // namespace epichead::sim
