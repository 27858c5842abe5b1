// Procedural textures. Drawing uses OpenCV; the noise fields are made tileable by blurring a
// wrapped copy (textures repeat on large planes).
#include "texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

namespace epichead::sim::texture {
namespace {

// Zero-mean, unit-deviation smooth noise (CV_32F) that tiles seamlessly.
cv::Mat smooth_noise(cv::Size size, double sigma_px, cv::RNG& rng) {
  cv::Mat n(size, CV_32F);
  rng.fill(n, cv::RNG::NORMAL, 0.0, 1.0);
  const int pad = std::min({static_cast<int>(std::ceil(3 * sigma_px)) + 1, size.width, size.height});
  cv::Mat padded;
  cv::copyMakeBorder(n, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::GaussianBlur(padded, padded, cv::Size(), sigma_px, sigma_px, cv::BORDER_REFLECT);
  cv::Mat out = padded(cv::Rect(pad, pad, size.width, size.height)).clone();
  cv::Scalar mean, dev;
  cv::meanStdDev(out, mean, dev);
  out = (out - mean[0]) / std::max(dev[0], 1e-9);
  return out;
}

// Adds `amount` * field (CV_32F) to every channel of an 8-bit BGR image.
void add_field(cv::Mat& bgr, const cv::Mat& field, double amount) {
  for (int y = 0; y < bgr.rows; ++y) {
    auto* p = bgr.ptr<cv::Vec3b>(y);
    const float* f = field.ptr<float>(y);
    for (int x = 0; x < bgr.cols; ++x)
      for (int c = 0; c < 3; ++c) p[x][c] = cv::saturate_cast<uchar>(p[x][c] + amount * f[x]);
  }
}

cv::Scalar random_colour(cv::RNG& rng, int lo, int hi) {
  return cv::Scalar(rng.uniform(lo, hi), rng.uniform(lo, hi), rng.uniform(lo, hi));
}

const std::array<const char*, 16> kWords = {"tea",   "store", "cool",  "dry",   "net",  "weight", "100g", "leaf",
                                            "blend", "since", "1897",  "best",  "before", "lot",  "black", "pure"};

std::string random_words(cv::RNG& rng, int n) {
  std::string s;
  for (int i = 0; i < n; ++i) {
    if (i) s += ' ';
    s += kWords[static_cast<std::size_t>(rng.uniform(0, static_cast<int>(kWords.size())))];
  }
  return s;
}

}  // namespace

cv::Mat clutter(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC3, random_colour(rng, 90, 170));
  const double scale = std::min(size.width, size.height) / 512.0;
  // Shelves and boxes: filled rectangles, some rotated, with darker outlines.
  for (int i = 0; i < 70; ++i) {
    const cv::Point2f c(rng.uniform(0.f, static_cast<float>(size.width)), rng.uniform(0.f, static_cast<float>(size.height)));
    const cv::Size2f s(static_cast<float>(rng.uniform(15.0, 140.0) * scale), static_cast<float>(rng.uniform(10.0, 120.0) * scale));
    const float angle = rng.uniform(0, 4) == 0 ? rng.uniform(-40.f, 40.f) : 0.f;
    cv::Point2f corners[4];
    cv::RotatedRect(c, s, angle).points(corners);
    std::vector<cv::Point> pts(corners, corners + 4);
    const cv::Scalar col = random_colour(rng, 20, 240);
    cv::fillConvexPoly(img, pts, col, cv::LINE_AA);
    cv::polylines(img, pts, true, col * 0.5, std::max(1, static_cast<int>(2 * scale)), cv::LINE_AA);
  }
  // Pipes and cables.
  for (int i = 0; i < 35; ++i) {
    const cv::Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point b(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::line(img, a, b, random_colour(rng, 10, 250), std::max(1, static_cast<int>(rng.uniform(1.0, 9.0) * scale)), cv::LINE_AA);
  }
  // Blobs.
  for (int i = 0; i < 25; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Size axes(static_cast<int>(rng.uniform(5.0, 50.0) * scale), static_cast<int>(rng.uniform(5.0, 50.0) * scale));
    cv::ellipse(img, c, axes, rng.uniform(0.0, 180.0), 0, 360, random_colour(rng, 20, 240), cv::FILLED, cv::LINE_AA);
  }
  // Labels.
  for (int i = 0; i < 20; ++i) {
    const cv::Point o(rng.uniform(0, size.width), rng.uniform(0, size.height));
    cv::putText(img, random_words(rng, 2), o, cv::FONT_HERSHEY_SIMPLEX, rng.uniform(0.4, 1.2) * scale,
                random_colour(rng, 0, 255), std::max(1, static_cast<int>(2 * scale)), cv::LINE_AA);
  }
  add_field(img, smooth_noise(size, 30 * scale, rng), 12);
  cv::GaussianBlur(img, img, cv::Size(), 0.7);
  return img;
}

cv::Mat steel_plate(cv::Size size, const std::vector<Seam>& seams, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC3, cv::Scalar(246, 246, 246));
  add_field(img, smooth_noise(size, 40, rng), 3.5);
  add_field(img, smooth_noise(size, 4, rng), 1.5);
  // Mill-scale specks and scratches.
  for (int i = 0; i < size.area() / 12000; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int v = rng.uniform(222, 240);
    cv::circle(img, c, rng.uniform(1, 3), cv::Scalar(v, v, v), cv::FILLED, cv::LINE_AA);
  }
  for (int i = 0; i < size.area() / 20000; ++i) {
    const cv::Point a(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const cv::Point b = a + cv::Point(rng.uniform(-40, 40), rng.uniform(-8, 8));
    cv::line(img, a, b, cv::Scalar(232, 232, 232), 1, cv::LINE_AA);
  }
  // Weld beads: a slightly darker band with a rippled centre, a faint heat tint beside it.
  for (const Seam& s : seams) {
    const cv::Point2d d = s.b - s.a;
    const double len = std::hypot(d.x, d.y);
    if (len < 1) continue;
    const cv::Point2d n(-d.y / len, d.x / len);
    cv::line(img, s.a, s.b, cv::Scalar(236, 238, 240), 9, cv::LINE_AA);
    cv::line(img, s.a, s.b, cv::Scalar(222, 222, 222), 4, cv::LINE_AA);
    for (double t = 0; t < len; t += 3) {
      const cv::Point2d p = s.a + d * (t / len) + n * rng.uniform(-0.6, 0.6);
      cv::circle(img, p, 1, cv::Scalar(212, 212, 212), cv::FILLED, cv::LINE_AA);
    }
  }
  cv::GaussianBlur(img, img, cv::Size(), 0.6);
  return img;
}

cv::Mat package_face(cv::Size size, int style, std::uint64_t seed) {
  cv::RNG rng(seed);
  struct Palette { cv::Scalar paper, band, ink, accent; const char* brand; };
  static const std::array<Palette, 6> palettes = {{
      {{235, 240, 245}, {40, 40, 200}, {30, 30, 30}, {20, 140, 220}, "EPIC TEA"},
      {{40, 40, 190}, {230, 235, 240}, {240, 240, 240}, {30, 200, 240}, "Earl Grey"},
      {{150, 70, 20}, {220, 225, 230}, {250, 250, 250}, {40, 180, 240}, "Assam"},
      {{230, 235, 240}, {60, 130, 30}, {20, 20, 20}, {40, 40, 200}, "Green"},
      {{60, 200, 230}, {120, 40, 40}, {30, 30, 30}, {240, 240, 240}, "Breakfast"},
      {{220, 230, 235}, {90, 90, 90}, {40, 40, 40}, {40, 40, 200}, "100 bags"},
  }};
  const Palette& p = palettes[static_cast<std::size_t>(std::clamp(style, 0, 5))];
  cv::Mat img(size, CV_8UC3, p.paper);
  const int w = size.width, h = size.height;
  const double s = std::min(w, h) / 300.0;
  // A colour band, a logo disc and its ring.
  const int band_y = static_cast<int>(h * rng.uniform(0.55, 0.7));
  cv::rectangle(img, cv::Rect(0, band_y, w, static_cast<int>(h * 0.18)), p.band, cv::FILLED);
  const cv::Point logo(static_cast<int>(w * rng.uniform(0.72, 0.82)), static_cast<int>(h * 0.3));
  cv::circle(img, logo, static_cast<int>(0.17 * std::min(w, h)), p.accent, cv::FILLED, cv::LINE_AA);
  cv::circle(img, logo, static_cast<int>(0.12 * std::min(w, h)), p.ink, std::max(1, static_cast<int>(3 * s)), cv::LINE_AA);
  // Brand name scaled to about half the width.
  int base = 0;
  const cv::Size brand = cv::getTextSize(p.brand, cv::FONT_HERSHEY_DUPLEX, 1.0, 2, &base);
  const double font = 0.55 * w / brand.width;
  cv::putText(img, p.brand, cv::Point(static_cast<int>(0.06 * w), static_cast<int>(0.3 * h)), cv::FONT_HERSHEY_DUPLEX,
              font, p.ink, std::max(1, static_cast<int>(2.2 * font)), cv::LINE_AA);
  // Small print.
  for (int i = 0; i < 4; ++i) {
    const int y = static_cast<int>(h * (0.4 + 0.045 * i));
    if (y > band_y - 4) break;
    cv::putText(img, random_words(rng, 5), cv::Point(static_cast<int>(0.06 * w), y), cv::FONT_HERSHEY_SIMPLEX,
                0.35 * s, p.ink, 1, cv::LINE_AA);
  }
  cv::putText(img, random_words(rng, 3), cv::Point(static_cast<int>(0.06 * w), band_y + static_cast<int>(h * 0.12)),
              cv::FONT_HERSHEY_SIMPLEX, 0.7 * s, p.paper, std::max(1, static_cast<int>(1.5 * s)), cv::LINE_AA);
  if (style == 2 || style == 5) {  // a barcode
    int x = static_cast<int>(0.08 * w);
    const int y0 = static_cast<int>(0.86 * h), y1 = static_cast<int>(0.96 * h);
    cv::rectangle(img, cv::Rect(x - 6, y0 - 6, static_cast<int>(0.4 * w) + 12, y1 - y0 + 12), cv::Scalar(250, 250, 250), cv::FILLED);
    while (x < 0.48 * w) {
      const int bar = rng.uniform(1, 4);
      cv::rectangle(img, cv::Rect(x, y0, bar, y1 - y0), cv::Scalar(10, 10, 10), cv::FILLED);
      x += bar + rng.uniform(1, 4);
    }
  }
  // A thin darker border: printed packages have a folded edge that keeps the box edges visible.
  cv::rectangle(img, cv::Rect(0, 0, w, h), p.paper * 0.75, std::max(2, static_cast<int>(2 * s)));
  add_field(img, smooth_noise(size, 20, rng), 2);
  cv::GaussianBlur(img, img, cv::Size(), 0.5);
  return img;
}

cv::Mat wood(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  // Grain: streaks along x (noise blurred far more along x than across), bent by a slow warp.
  cv::Mat streaks(size, CV_32F), fine(size, CV_32F);
  rng.fill(streaks, cv::RNG::NORMAL, 0.0, 1.0);
  rng.fill(fine, cv::RNG::NORMAL, 0.0, 1.0);
  auto stretch = [&](cv::Mat& m, double sx, double sy) {
    const int px = std::min(size.width, static_cast<int>(3 * sx) + 1), py = std::min(size.height, static_cast<int>(3 * sy) + 1);
    cv::Mat padded;
    cv::copyMakeBorder(m, padded, py, py, px, px, cv::BORDER_WRAP);
    cv::GaussianBlur(padded, padded, cv::Size(), sx, sy);
    m = padded(cv::Rect(px, py, size.width, size.height)).clone();
    cv::normalize(m, m, -1, 1, cv::NORM_MINMAX);
  };
  stretch(streaks, 60, 2.5);
  stretch(fine, 12, 0.7);
  cv::Mat warp = smooth_noise(size, 40, rng);
  cv::Mat img(size, CV_8UC3);
  const double rings = 6;  // whole periods across the height: tiles vertically
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const double phase = 2 * std::numbers::pi * rings * y / size.height + 2.0 * warp.at<float>(y, x);
      const double v = 0.82 + 0.08 * std::sin(phase) + 0.07 * streaks.at<float>(y, x) + 0.04 * fine.at<float>(y, x);
      img.at<cv::Vec3b>(y, x) = {cv::saturate_cast<uchar>(62 * v), cv::saturate_cast<uchar>(108 * v),
                                 cv::saturate_cast<uchar>(160 * v)};
    }
  return img;
}

cv::Mat concrete(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC3, cv::Scalar(128, 133, 138));
  add_field(img, smooth_noise(size, 60, rng), 10);
  add_field(img, smooth_noise(size, 6, rng), 5);
  add_field(img, smooth_noise(size, 1, rng), 6);
  for (int i = 0; i < size.area() / 4000; ++i) {
    const cv::Point c(rng.uniform(0, size.width), rng.uniform(0, size.height));
    const int v = rng.uniform(70, 190);
    cv::circle(img, c, rng.uniform(1, 3), cv::Scalar(v, v, v + 5), cv::FILLED, cv::LINE_AA);
  }
  return img;
}

cv::Mat plaster(cv::Size size, cv::Scalar bgr, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC3, bgr);
  add_field(img, smooth_noise(size, 30, rng), 3);
  add_field(img, smooth_noise(size, 1.2, rng), 2);
  return img;
}

cv::Mat fabric(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat img(size, CV_8UC3);
  cv::Mat slub = smooth_noise(size, 8, rng);
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const int weave = ((x / 2 + y / 2) % 2) ? 4 : -4;
      const int v = cv::saturate_cast<uchar>(238 + weave + 4 * slub.at<float>(y, x));
      img.at<cv::Vec3b>(y, x) = {static_cast<uchar>(v), static_cast<uchar>(v), static_cast<uchar>(v)};
    }
  return img;
}

cv::Mat parquet(cv::Size size, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat grain = wood(size, seed + 1);
  cv::Mat img(size, CV_8UC3);
  // Planks: rows of 1/8 of the height, staggered joints.
  const int rows = 8, plank_h = size.height / rows;
  for (int r = 0; r < rows; ++r) {
    const int offset = rng.uniform(0, size.width);
    const int plank_w = size.width / 2;
    for (int k = 0; k < 3; ++k) {
      const double shade = rng.uniform(0.8, 1.1);
      for (int y = r * plank_h; y < (r + 1) * plank_h; ++y)
        for (int xi = 0; xi < plank_w; ++xi) {
          const int x = (offset + k * plank_w + xi) % size.width;
          const cv::Vec3b g = grain.at<cv::Vec3b>(y, (xi * 3) % size.width);
          const bool joint = y == r * plank_h || xi == 0;
          const double f = joint ? 0.45 : shade;
          img.at<cv::Vec3b>(y, x) = {cv::saturate_cast<uchar>(g[0] * f), cv::saturate_cast<uchar>(g[1] * f),
                                     cv::saturate_cast<uchar>(g[2] * f)};
        }
    }
  }
  return img;
}

}  // namespace epichead::sim::texture
