// The environment layer. Why by hand: cv::warpPerspective allocates per block and would need a
// mask and a masked copy per plane; here each plane is drawn along its polygon's row spans.
// Why row by row over all instants (not instant by instant over the whole image): the frame's
// linear buffer (W x H x 3 floats, several MB) then stays in the first-level cache while the
// instants are added into it, instead of streaming through memory once per instant.
#include "render_environment.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <opencv2/imgproc.hpp>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace epichead::sim::render {
namespace {

// (s + n/2) / n for 0 <= s <= 255 n, as a multiply and shift when that is exact for every such
// s (checked once), so that the column pass of the blur vectorises.
struct RoundedDivide {
  std::uint32_t n = 1, half = 0, mul = 1;
  int shift = 0;
  bool exact = true;

  explicit RoundedDivide(std::uint32_t n_) : n(n_), half(n_ / 2) {
    shift = 23;  // (255 n + n) * mul stays below 2^32
    mul = static_cast<std::uint32_t>(((std::uint64_t{1} << shift) + n - 1) / n);
    for (std::uint32_t s = 0; s <= 255 * n && exact; ++s)
      exact = static_cast<std::uint32_t>((static_cast<std::uint64_t>(s + half) * mul) >> shift) == (s + half) / n &&
              static_cast<std::uint64_t>(s + half) * mul < (std::uint64_t{1} << 32);
  }
  std::uint32_t operator()(std::uint32_t s) const { return exact ? ((s + half) * mul) >> shift : (s + half) / n; }
};

// A colour as the row buffer holds it: bytes B, G, R, 0 in memory.
std::uint32_t pack(const cv::Vec3b& c) {
  std::uint32_t v = 0;
  const std::uint8_t bytes[4] = {c[0], c[1], c[2], 0};
  std::memcpy(&v, bytes, 4);
  return v;
}

}  // namespace

EnvironmentLayer::EnvironmentLayer(const Scene& scene, const IdealView& view, double gamma, const float (&decode_lut)[256])
    : scene_(&scene), view_(view) {
  std::copy(std::begin(decode_lut), std::end(decode_lut), decode_lut_);
  const Eigen::Vector3d l = scene.light.direction_world.normalized();
  const double lit = scene.light.ambient + scene.light.diffuse * std::max(0.0, l.z());
  keep_ = lit > 0 ? static_cast<float>(scene.light.ambient / lit) : 1.f;
  setup_textures(gamma);
  const auto W = static_cast<std::size_t>(view_.W);
  row_.assign(W, 0);
  receiver_row_.assign(W, 0);
  texel_offset_.assign(W, 0);
  frac_u_.assign(W, 0);
  frac_v_.assign(W, 0);
  col_sums_.assign(W, 0);
  blur_tmp_.create(view_.H, view_.W, CV_8U);
}

void EnvironmentLayer::setup_textures(double gamma) {
  auto encode8 = [&](float lin) {
    const double g = gamma > 0 ? gamma : 1.0;
    return cv::saturate_cast<uchar>(255.0 * std::pow(std::clamp(static_cast<double>(lin), 0.0, 1.0), 1.0 / g));
  };
  for (const auto& plane : scene_->background.planes) {
    if (plane.texture < 0) {
      tex8_.emplace_back();
      plain8_.push_back({encode8(plane.tint_bgr[0]), encode8(plane.tint_bgr[1]), encode8(plane.tint_bgr[2])});
      continue;
    }
    cv::Mat t8 = scene_->textures[static_cast<std::size_t>(plane.texture)];
    if (plane.tex_px_per_m > 0) {
      // Repeat the texture over the whole plane once here, so the warp never wraps.
      const double scale = std::min(1.0, 4096.0 / (std::max(plane.width_m, plane.height_m) * plane.tex_px_per_m));
      const int w = std::max(1, static_cast<int>(std::lround(plane.width_m * plane.tex_px_per_m * scale)));
      const int h = std::max(1, static_cast<int>(std::lround(plane.height_m * plane.tex_px_per_m * scale)));
      cv::Mat tile = t8;
      if (scale < 1) cv::resize(t8, tile, cv::Size(), scale, scale, cv::INTER_AREA);
      cv::Mat tiled;
      cv::repeat(tile, h / tile.rows + 1, w / tile.cols + 1, tiled);
      t8 = tiled(cv::Rect(0, 0, w, h));
    }
    // Tint in linear light, back to 8-bit: one table per channel.
    cv::Mat lut(1, 256, CV_8UC3);
    for (int i = 0; i < 256; ++i)
      for (int ch = 0; ch < 3; ++ch) lut.at<cv::Vec3b>(0, i)[ch] = encode8(decode_lut_[i] * plane.tint_bgr[ch]);
    cv::Mat tinted, bgra;
    cv::LUT(t8, lut, tinted);
    cv::cvtColor(tinted, bgra, cv::COLOR_BGR2BGRA);  // 4 bytes a texel: one load per texel pair
    tex8_.push_back(bgra);
    plain8_.push_back({0, 0, 0});
  }
  plain8_.push_back({encode8(scene_->background.plain_bgr[0]), encode8(scene_->background.plain_bgr[1]),
                     encode8(scene_->background.plain_bgr[2])});
}

void EnvironmentLayer::prepare_instant(const EnvironmentInstant& instant, bool shadows, PlaneView* planes,
                                       ShadowView& shadow) {
  const Eigen::Isometry3d cam_T_world = instant.world_T_cam.inverse();
  const auto& scene_planes = scene_->background.planes;
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << view_.fx, 0, view_.cx, 0, view_.fy, view_.cy, 0, 0, 1).finished();
  for (std::size_t i = 0; i < scene_planes.size(); ++i) {
    const EnvironmentPlane& p = scene_planes[i];
    PlaneView& pv = planes[i];
    pv.visible = false;
    const Eigen::Isometry3d cam_T_plane = cam_T_world * p.world_T_plane;
    // The plane is seen only from its +z side.
    if (cam_T_plane.linear().col(2).dot(cam_T_plane.translation()) >= 0) continue;
    const double hw = p.width_m / 2, hh = p.height_m / 2;
    Eigen::Vector3f corners[4];
    const double cs[4][2] = {{-hw, -hh}, {hw, -hh}, {hw, hh}, {-hw, hh}};
    for (int k = 0; k < 4; ++k) corners[k] = (cam_T_plane * Eigen::Vector3d(cs[k][0], cs[k][1], 0)).cast<float>();
    int x0 = 0, x1 = 0;
    if (!pv.poly.project(view_, corners, 4, x0, x1)) continue;
    const cv::Mat& tex = tex8_[i];
    if (!tex.empty()) {
      // Ideal pixel -> plane (s, t) -> texture pixel.
      Eigen::Matrix3d px_from_st;
      px_from_st.col(0) = K * cam_T_plane.linear().col(0);
      px_from_st.col(1) = K * cam_T_plane.linear().col(1);
      px_from_st.col(2) = K * cam_T_plane.translation();
      const double su = tex.cols / p.width_m, sv = tex.rows / p.height_m;
      Eigen::Matrix3d tex_from_st;
      tex_from_st << su, 0, hw * su - 0.5, 0, -sv, hh * sv - 0.5, 0, 0, 1;
      pv.tex_from_px = tex_from_st * px_from_st.inverse();
      if (!pv.tex_from_px.allFinite()) continue;
    }
    pv.visible = true;
  }
  shadow.box = cv::Rect();
  if (!shadows) return;
  if (shadow.mask.empty()) shadow.mask = cv::Mat::zeros(view_.H, view_.W, CV_8U);  // kept zero outside `box`
  add_shadow(scene_->object_mesh, instant.world_T_obj, cam_T_world, shadow.mask, shadow.box);
  for (const auto& m : scene_->scenery) add_shadow(m, Eigen::Isometry3d::Identity(), cam_T_world, shadow.mask, shadow.box);
  if (shadow.box.area() == 0) return;
  const double softness = scene_->shadows.softness_px;
  const int pad = static_cast<int>(std::ceil(3 * softness)) + 1;
  shadow.box = cv::Rect(shadow.box.x - pad, shadow.box.y - pad, shadow.box.width + 2 * pad, shadow.box.height + 2 * pad) &
               cv::Rect(0, 0, view_.W, view_.H);
  if (softness > 0) soften(shadow.mask, shadow.box, softness);
}

// Shadow of one posed mesh on the ground plane, filled into `mask`; grows `box`.
void EnvironmentLayer::add_shadow(const Mesh& mesh, const Eigen::Isometry3d& world_T_mesh,
                                  const Eigen::Isometry3d& cam_T_world, cv::Mat& mask, cv::Rect& box) {
  const Eigen::Vector3d l = scene_->light.direction_world.normalized();
  if (l.z() < 0.05) return;
  const double g = scene_->shadows.ground_z_m;
  const Eigen::Vector3f light_mesh = (world_T_mesh.linear().transpose() * l).cast<float>();
  ScreenPolygon poly;
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3f& p0 = mesh.positions[static_cast<std::size_t>(tri[0])];
    const Eigen::Vector3f& p1 = mesh.positions[static_cast<std::size_t>(tri[1])];
    const Eigen::Vector3f& p2 = mesh.positions[static_cast<std::size_t>(tri[2])];
    // A closed solid's shadow is the union of the shadows of its faces toward the light.
    if (mesh.closed && (p1 - p0).cross(p2 - p0).dot(light_mesh) <= 0) continue;
    Eigen::Vector3f c[3];
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d pw = world_T_mesh * mesh.positions[static_cast<std::size_t>(tri[static_cast<std::size_t>(k)])].cast<double>();
      const Eigen::Vector3d on_ground = pw - std::max(0.0, pw.z() - g) / l.z() * l;
      c[k] = (cam_T_world * on_ground).cast<float>();
    }
    int x0 = 0, x1 = 0;
    if (!poly.project(view_, c, 3, x0, x1)) continue;
    for (int y = poly.y0; y < poly.y1; ++y) {
      int s0 = 0, s1 = 0;
      if (poly.row_span(y, view_.W, s0, s1)) std::fill(mask.ptr<uchar>(y) + s0, mask.ptr<uchar>(y) + s1 + 1, uchar{255});
    }
    const cv::Rect b(x0, poly.y0, x1 - x0, poly.y1 - poly.y0);
    box = box.area() == 0 ? b : (box | b);
  }
}

// Separable box blur, twice (close to a Gaussian of sigma_px), of a mask region, in place.
// Each 1-D pass rounds to 8 bits and repeats the region's border pixels.
void EnvironmentLayer::soften(cv::Mat& mask, const cv::Rect& r, double sigma_px) {
  const int radius = std::max(1, static_cast<int>(std::lround((std::sqrt(6 * sigma_px * sigma_px + 1) - 1) / 2)));
  const int n = 2 * radius + 1;
  const RoundedDivide divide(static_cast<std::uint32_t>(n));
  const int w = r.width, h = r.height;
  for (int pass = 0; pass < 2; ++pass) {
    // Rows: mask -> blur_tmp_. Window sums as shifted adds (vectorise; the radius is small),
    // the region's border pixels repeated outside it.
    std::int32_t* sums = col_sums_.data();
    for (int y = r.y; y < r.y + h; ++y) {
      const uchar* src = mask.ptr<uchar>(y) + r.x;
      uchar* dst = blur_tmp_.ptr<uchar>(y) + r.x;
      const int inner0 = std::min(radius, w), inner1 = std::max(inner0, w - radius);  // [inner0, inner1): no clamping
      for (int x = inner0; x < inner1; ++x) sums[x] = 0;
      for (int k = -radius; k <= radius; ++k)
        for (int x = inner0; x < inner1; ++x) sums[x] += src[x + k];
      auto clamped_sum = [&](int x) {
        std::int32_t sum = 0;
        for (int k = -radius; k <= radius; ++k) sum += src[std::clamp(x + k, 0, w - 1)];
        sums[x] = sum;
      };
      for (int x = 0; x < inner0; ++x) clamped_sum(x);
      for (int x = inner1; x < w; ++x) clamped_sum(x);
      if (divide.exact)
        for (int x = 0; x < w; ++x)
          dst[x] = static_cast<uchar>((static_cast<std::uint32_t>(sums[x]) + divide.half) * divide.mul >> divide.shift);
      else
        for (int x = 0; x < w; ++x) dst[x] = static_cast<uchar>(divide(static_cast<std::uint32_t>(sums[x])));
    }
    // Columns: blur_tmp_ -> mask, running sums of all columns at once (contiguous, vectorises).
    std::fill(sums, sums + w, 0);
    for (int k = -radius; k <= radius; ++k) {
      const uchar* src = blur_tmp_.ptr<uchar>(r.y + std::clamp(k, 0, h - 1)) + r.x;
      for (int x = 0; x < w; ++x) sums[x] += src[x];
    }
    for (int y = 0; y < h; ++y) {
      uchar* dst = mask.ptr<uchar>(r.y + y) + r.x;
      const uchar* add = blur_tmp_.ptr<uchar>(r.y + std::min(y + radius + 1, h - 1)) + r.x;
      const uchar* sub = blur_tmp_.ptr<uchar>(r.y + std::max(y - radius, 0)) + r.x;
      if (divide.exact) {
        for (int x = 0; x < w; ++x) {
          dst[x] = static_cast<uchar>((static_cast<std::uint32_t>(sums[x]) + divide.half) * divide.mul >> divide.shift);
          sums[x] += add[x] - sub[x];
        }
      } else {
        for (int x = 0; x < w; ++x) {
          dst[x] = static_cast<uchar>(divide(static_cast<std::uint32_t>(sums[x])));
          sums[x] += add[x] - sub[x];
        }
      }
    }
  }
}

void EnvironmentLayer::warp_row(const PlaneView& pv, const cv::Mat& tex, int y, int x0, int x1, std::uint32_t* dst) {
  const int n = x1 - x0 + 1;
  // Texel coordinates of the row's pixels in float, relative to the row's first pixel (whose
  // homogeneous coordinates are exact in double), so the loop vectorises four pixels at a time.
  // NaN coordinates (none inside a clipped polygon) land on texel 0, not outside the texture.
  const Eigen::Vector3d h0 = pv.tex_from_px * Eigen::Vector3d(x0, y, 1);
  const float hx0 = static_cast<float>(h0.x()), hy0 = static_cast<float>(h0.y()), hz0 = static_cast<float>(h0.z());
  const float sx = static_cast<float>(pv.tex_from_px(0, 0)), sy = static_cast<float>(pv.tex_from_px(1, 0));
  const float sz = static_cast<float>(pv.tex_from_px(2, 0));
  const float umax = static_cast<float>(tex.cols - 1) - 1e-3f, vmax = static_cast<float>(tex.rows - 1) - 1e-3f;
  const int stride = static_cast<int>(tex.step[0]);
  std::int32_t* offset = texel_offset_.data();
  std::int32_t* fu = frac_u_.data();
  std::int32_t* fv = frac_v_.data();
  for (int i = 0; i < n; ++i) {
    const float k = static_cast<float>(i);
    const float inv = 1.f / (hz0 + k * sz);
    const float us = (hx0 + k * sx) * inv, vs = (hy0 + k * sy) * inv;
    const float u = std::min(std::max(0.f, us), umax), v = std::min(std::max(0.f, vs), vmax);  // NaN -> 0
    const int iu = static_cast<int>(u), iv = static_cast<int>(v);
    fu[i] = static_cast<int>((u - static_cast<float>(iu)) * 256.f);
    fv[i] = static_cast<int>((v - static_cast<float>(iv)) * 256.f);
    offset[i] = iv * stride + 4 * iu;
  }
  // Bilinear in 8-bit fixed point (1/256 texel), all four bytes of a texel at once.
  const std::uint8_t* base = tex.data;
  std::uint32_t* out = dst + x0;
#if defined(__SSE4_1__)
  const __m128i round = _mm_set1_epi32(1 << 15);
  for (int i = 0; i < n; ++i) {
    const std::uint8_t* p = base + offset[i];
    const __m128i wu = _mm_unpacklo_epi64(_mm_set1_epi16(static_cast<short>(256 - fu[i])), _mm_set1_epi16(static_cast<short>(fu[i])));
    // Texels (iu, iv), (iu + 1, iv) and the row below, 16 bits a channel; products fit 16 bits unsigned.
    __m128i a = _mm_mullo_epi16(_mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p))), wu);
    __m128i b = _mm_mullo_epi16(_mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(p + stride))), wu);
    const __m128i top = _mm_cvtepu16_epi32(_mm_add_epi16(a, _mm_srli_si128(a, 8)));
    const __m128i bottom = _mm_cvtepu16_epi32(_mm_add_epi16(b, _mm_srli_si128(b, 8)));
    __m128i r = _mm_add_epi32(_mm_mullo_epi32(top, _mm_set1_epi32(256 - fv[i])), _mm_mullo_epi32(bottom, _mm_set1_epi32(fv[i])));
    r = _mm_srli_epi32(_mm_add_epi32(r, round), 16);
    r = _mm_packus_epi16(_mm_packus_epi32(r, r), r);
    out[i] = static_cast<std::uint32_t>(_mm_cvtsi128_si32(r));
  }
#else
  for (int i = 0; i < n; ++i) {
    const std::uint8_t* r0 = base + offset[i];
    const std::uint8_t* r1 = r0 + stride;
    const int au = fu[i], av = fv[i];
    std::uint32_t texel = 0;
    for (int ch = 0; ch < 3; ++ch) {
      const int top = r0[ch] * (256 - au) + r0[ch + 4] * au, bottom = r1[ch] * (256 - au) + r1[ch + 4] * au;
      texel |= static_cast<std::uint32_t>((top * (256 - av) + bottom * av + (1 << 15)) >> 16) << (8 * ch);
    }
    out[i] = texel;
  }
#endif
}

void EnvironmentLayer::draw_row(const PlaneView* planes, int y, bool receivers) {
  std::uint32_t* dst = row_.data();
  const int W = view_.W;
  std::fill(dst, dst + W, pack(plain8_.back()));
  if (receivers) std::fill(receiver_row_.begin(), receiver_row_.end(), std::uint8_t{0});
  const auto& scene_planes = scene_->background.planes;
  for (std::size_t i = 0; i < scene_planes.size(); ++i) {
    const PlaneView& pv = planes[i];
    if (!pv.visible || y < pv.poly.y0 || y >= pv.poly.y1) continue;
    int x0 = 0, x1 = 0;
    if (!pv.poly.row_span(y, W, x0, x1)) continue;
    if (receivers)
      std::fill(receiver_row_.data() + x0, receiver_row_.data() + x1 + 1, scene_planes[i].receives_shadow ? 255 : 0);
    const cv::Mat& tex = tex8_[i];
    if (tex.empty()) {
      std::fill(dst + x0, dst + x1 + 1, pack(plain8_[i]));
      continue;
    }
    warp_row(pv, tex, y, x0, x1, dst);
  }
}

void EnvironmentLayer::render(std::span<const EnvironmentInstant> instants, bool shadows, float* linear) {
  const std::size_t n_inst = instants.size();
  const std::size_t n_planes = scene_->background.planes.size();
  if (plane_views_.size() < n_inst * n_planes) plane_views_.resize(n_inst * n_planes);
  if (shadows_.size() < n_inst) shadows_.resize(n_inst);
  for (std::size_t j = 0; j < n_inst; ++j) prepare_instant(instants[j], shadows, plane_views_.data() + j * n_planes, shadows_[j]);

  const float weight = 1.f / static_cast<float>(n_inst);
  float lut[256];
  for (int i = 0; i < 256; ++i) lut[i] = weight * decode_lut_[i];
  const int W = view_.W;
  // The row as bytes B, G, R, unused.
  const std::uint8_t* src = reinterpret_cast<const std::uint8_t*>(row_.data());
  const std::uint8_t* r = receiver_row_.data();
  for (int y = 0; y < view_.H; ++y) {
    float* dst = linear + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
    for (std::size_t j = 0; j < n_inst; ++j) {
      const ShadowView& sh = shadows_[j];
      const bool shadow_row = sh.box.area() > 0 && y >= sh.box.y && y < sh.box.y + sh.box.height;
      draw_row(plane_views_.data() + j * n_planes, y, shadow_row);
      const bool first = j == 0;
      if (!shadow_row) {
        if (first)
          for (int x = 0; x < W; ++x) {
            dst[3 * x] = lut[src[4 * x]]; dst[3 * x + 1] = lut[src[4 * x + 1]]; dst[3 * x + 2] = lut[src[4 * x + 2]];
          }
        else
          for (int x = 0; x < W; ++x) {
            dst[3 * x] += lut[src[4 * x]]; dst[3 * x + 1] += lut[src[4 * x + 1]]; dst[3 * x + 2] += lut[src[4 * x + 2]];
          }
        continue;
      }
      // Shadowed floor keeps the ambient share of its light.
      const uchar* s = sh.mask.ptr<uchar>(y);
      for (int x = 0; x < W; ++x) {
        float f = 1.f;
        if (s[x] != 0 && r[x] != 0)
          f = 1.f - (1.f - keep_) * (static_cast<float>(s[x]) / 255.f) * (static_cast<float>(r[x]) / 255.f);
        for (int ch = 0; ch < 3; ++ch) {
          const float v = f * lut[src[4 * x + ch]];
          dst[3 * x + ch] = first ? v : dst[3 * x + ch] + v;
        }
      }
    }
  }
  for (std::size_t j = 0; j < n_inst; ++j) {  // leave the masks zero for the next frame
    ShadowView& sh = shadows_[j];
    for (int y = sh.box.y; y < sh.box.y + sh.box.height; ++y)
      std::fill(sh.mask.ptr<uchar>(y) + sh.box.x, sh.mask.ptr<uchar>(y) + sh.box.x + sh.box.width, uchar{0});
  }
}

}  // namespace epichead::sim::render
