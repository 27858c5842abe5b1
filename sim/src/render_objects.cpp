// The objects at one sub-frame: triangles rasterised exactly (fixed-point edge functions,
// top-left rule) at M sample positions a pixel with a depth buffer, tile by tile, shaded once per
// pixel and triangle (multisampling), and resolved against the environment behind them.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

#include "renderer_impl.h"

namespace epichead::sim {
namespace {

using render::ceil_div;
using render::floor_div;
using render::FrameMaterial;
using render::kDecodeFine;
using render::kFixOne;
using render::kMaxSamplesPerFrame;
using render::kMaxSamplesPerSubframe;
using render::kTile;
using render::MipLevel;
using render::RasterTriangle;

// Bilinear, repeating; returns linear factors.
cv::Vec3f sample_texture(const MipLevel& level, float u, float v, const float* decode) {
  const cv::Mat& tex = level.image;
  const float fw = static_cast<float>(tex.cols), fh = static_cast<float>(tex.rows);
  // Wrap only when outside: most faces map into their texture without repeating.
  if (!(u >= 0 && u < fw - 1)) u -= fw * std::floor(u * level.inv_cols);
  if (!(v >= 0 && v < fh - 1)) v -= fh * std::floor(v * level.inv_rows);
  int iu = static_cast<int>(u), iv = static_cast<int>(v);
  const float au = u - static_cast<float>(iu), av = v - static_cast<float>(iv);
  iu = std::clamp(iu, 0, tex.cols - 1);
  iv = std::clamp(iv, 0, tex.rows - 1);
  const int iu1 = iu + 1 == tex.cols ? 0 : iu + 1, iv1 = iv + 1 == tex.rows ? 0 : iv + 1;
  const uchar* r0 = tex.ptr<uchar>(iv);
  const uchar* r1 = tex.ptr<uchar>(iv1);
  const uchar *p00 = r0 + 4 * iu, *p01 = r0 + 4 * iu1, *p10 = r1 + 4 * iu, *p11 = r1 + 4 * iu1;
  const float w00 = (1 - au) * (1 - av) * kDecodeFine, w01 = au * (1 - av) * kDecodeFine;
  const float w10 = (1 - au) * av * kDecodeFine, w11 = au * av * kDecodeFine;
  cv::Vec3f out;
#if defined(__SSE4_1__)
  // All channels of a texel at once; the same operations in the same order as the scalar code.
  auto texel = [](const uchar* p) {
    std::int32_t bgra = 0;
    std::memcpy(&bgra, p, 4);
    return _mm_cvtepi32_ps(_mm_cvtepu8_epi32(_mm_cvtsi32_si128(bgra)));
  };
  __m128 e = _mm_mul_ps(_mm_set1_ps(w00), texel(p00));
  e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w01), texel(p01)));
  e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w10), texel(p10)));
  e = _mm_add_ps(e, _mm_mul_ps(_mm_set1_ps(w11), texel(p11)));
  alignas(16) std::int32_t idx[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(idx), _mm_cvttps_epi32(_mm_add_ps(e, _mm_set1_ps(0.5f))));
  for (int ch = 0; ch < 3; ++ch) out[ch] = decode[idx[ch]];
#else
  for (int ch = 0; ch < 3; ++ch) {
    const float e = w00 * p00[ch] + w01 * p01[ch] + w10 * p10[ch] + w11 * p11[ch];
    out[ch] = decode[static_cast<int>(e + 0.5f)];
  }
#endif
  return out;
}

}  // namespace

// Objects at one sub-frame: their samples replace the environment, added to `corr` as
// (sample - environment) * weight, so that the environment itself is drawn once per frame.
void Renderer::Impl::object_pass(const SubFrame& sf, int sub_index, int n_sub, float weight) {
  const Eigen::Isometry3d cam_T_world = sf.world_T_cam.inverse();
  tris.clear();
  add_mesh(scene.object_mesh, cam_T_world * sf.world_T_obj, sf.world_T_obj);
  for (const auto& m : scene.scenery) add_mesh(m, cam_T_world, Eigen::Isometry3d::Identity());
  for (std::size_t i = 0; i < scene.occluders.size() && i < sf.world_T_occluders.size(); ++i)
    add_mesh(scene.occluders[i], cam_T_world * sf.world_T_occluders[i], sf.world_T_occluders[i]);
  int bx0 = W, by0 = H, bx1 = -1, by1 = -1;
  for (const auto& t : tris) {
    bx0 = std::min(bx0, t.x0); by0 = std::min(by0, t.y0);
    bx1 = std::max(bx1, t.x1); by1 = std::max(by1, t.y1);
  }
  if (bx1 < bx0) return;
  const auto& pat = pattern(std::min(n_sub * M, kMaxSamplesPerFrame));
  const int total = static_cast<int>(pat.size());
  Eigen::Vector2i offsets[kMaxSamplesPerSubframe];
  for (int k = 0; k < M; ++k) offsets[k] = pat[static_cast<std::size_t>((sub_index + n_sub * k) % total)];
  const cv::Rect box(bx0, by0, bx1 - bx0 + 1, by1 - by0 + 1);
  // Grow the corrected area, zeroing what is new to it.
  const cv::Rect grown = corr_box.area() > 0 ? (corr_box | box) : box;
  for (int y = grown.y; y < grown.y + grown.height; ++y) {
    float* c = corr.ptr<float>(y);
    for (int x = grown.x; x < grown.x + grown.width; ++x)
      if (!corr_box.contains({x, y})) c[3 * x] = c[3 * x + 1] = c[3 * x + 2] = 0.f;
  }
  corr_box = grown;
  for (int ty = by0; ty <= by1; ty += kTile)
    for (int tx = bx0; tx <= bx1; tx += kTile) {
      const cv::Rect tile(tx, ty, std::min(kTile, bx1 + 1 - tx), std::min(kTile, by1 + 1 - ty));
      bool any = false;
      for (const auto& t : tris) {
        if (t.x1 < tile.x || t.x0 >= tile.x + tile.width || t.y1 < tile.y || t.y0 >= tile.y + tile.height) continue;
        if (!any) std::fill(depth.begin(), depth.end(), 0.f);
        any = true;
        rasterise(t, offsets, tile);
      }
      if (any) resolve(tile, weight / static_cast<float>(M));
    }
}

// Rasterises one triangle at the M sample positions of this sub-frame. Coverage and depth are
// per sample (exact edges); the colour is evaluated once per pixel at the centroid of the
// samples the triangle wins (multisampling: texture lookups dominate otherwise).
void Renderer::Impl::rasterise(const RasterTriangle& t, const Eigen::Vector2i* offsets, const cv::Rect& tile) {
  const FrameMaterial& fm = materials[static_cast<std::size_t>(t.material)];
  const MipLevel* tex = fm.texture >= 0 ? &tex_mips[static_cast<std::size_t>(fm.texture)][static_cast<std::size_t>(t.mip)] : nullptr;
  float ox[kMaxSamplesPerSubframe], oy[kMaxSamplesPerSubframe];
  float dw[kMaxSamplesPerSubframe];  // 1/z at a sample minus 1/z at the pixel centre
  for (int k = 0; k < M; ++k) {
    ox[k] = static_cast<float>(offsets[k].x()) / kFixOne;
    oy[k] = static_cast<float>(offsets[k].y()) / kFixOne;
    dw[k] = t.w[0] * ox[k] + t.w[1] * oy[k];
  }
  std::int64_t ex[3];  // edge function step per pixel in x
  for (int i = 0; i < 3; ++i) ex[i] = -(t.Y[(i + 2) % 3] - t.Y[(i + 1) % 3]) * kFixOne;
  std::int64_t lo[kMaxSamplesPerSubframe], hi[kMaxSamplesPerSubframe];
  // The tile, relative to the triangle's box.
  const std::int64_t tile_lo = std::max(0, tile.x - t.x0), tile_hi = std::min(t.x1, tile.x + tile.width - 1) - t.x0;
  const int y_end = std::min(t.y1, tile.y + tile.height - 1);
  for (int y = std::max(t.y0, tile.y); y <= y_end; ++y) {
    // Per sample: the span of this row where all three edge functions are >= 0 (exact).
    std::int64_t span_lo = tile_hi + 1, span_hi = -1;
    for (int k = 0; k < M; ++k) {
      const std::int64_t sx0 = static_cast<std::int64_t>(t.x0) * kFixOne + offsets[k].x();
      const std::int64_t sy = static_cast<std::int64_t>(y) * kFixOne + offsets[k].y();
      lo[k] = tile_lo;
      hi[k] = tile_hi;
      for (int i = 0; i < 3 && lo[k] <= hi[k]; ++i) {
        const int a1 = (i + 1) % 3, a2 = (i + 2) % 3;
        const std::int64_t e0 =
            (t.X[a2] - t.X[a1]) * (sy - t.Y[a1]) - (t.Y[a2] - t.Y[a1]) * (sx0 - t.X[a1]) + t.bias[i];
        if (ex[i] > 0) lo[k] = std::max(lo[k], ceil_div(-e0, ex[i]));
        else if (ex[i] < 0) hi[k] = std::min(hi[k], floor_div(e0, -ex[i]));
        else if (e0 < 0) hi[k] = -1;
      }
      if (lo[k] <= hi[k]) {
        span_lo = std::min(span_lo, lo[k]);
        span_hi = std::max(span_hi, hi[k]);
      }
    }
    if (span_lo > span_hi) continue;
    const float fy = static_cast<float>(y - t.y0);
    const float w_row = t.w[1] * fy + t.w[2];
    // Index in the tile buffers of the pixel at xi = 0.
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(y - tile.y) * kTile + (t.x0 - tile.x);
    for (std::int64_t xi = span_lo; xi <= span_hi; ++xi) {
      const auto idx = static_cast<std::size_t>(row + xi);
      const float fxp = static_cast<float>(xi);
      unsigned won = 0;
      float cx_sum = 0, cy_sum = 0;
      for (int k = 0; k < M; ++k) {
        if (xi < lo[k] || xi > hi[k]) continue;
        const float w = t.w[0] * fxp + w_row + dw[k];
        float& d = depth[idx * static_cast<std::size_t>(M) + static_cast<std::size_t>(k)];
        if (!(w > d)) continue;
        d = w;
        won |= 1u << k;
        cx_sum += ox[k];
        cy_sum += oy[k];
      }
      if (!won) continue;
      const float n_won = static_cast<float>(std::popcount(won));
      const float px = fxp + cx_sum / n_won, py = fy + cy_sum / n_won;
      const float inv = 1.f / (t.w[0] * px + t.w[1] * py + t.w[2]);
      const float shade = (t.s[0] * px + t.s[1] * py + t.s[2]) * inv;
      float c0 = fm.albedo[0] * shade, c1 = fm.albedo[1] * shade, c2 = fm.albedo[2] * shade;
      if (tex) {
        const float u = (t.u[0] * px + t.u[1] * py + t.u[2]) * inv, v = (t.v[0] * px + t.v[1] * py + t.v[2]) * inv;
        const cv::Vec3f texel = sample_texture(*tex, (u + 0.5f) * tex->su - 0.5f, (v + 0.5f) * tex->sv - 0.5f, decode_fine);
        c0 *= texel[0]; c1 *= texel[1]; c2 *= texel[2];
      }
      for (int k = 0; k < M; ++k) {
        if (!(won & (1u << k))) continue;
        float* out = color.data() + 3 * (idx * static_cast<std::size_t>(M) + static_cast<std::size_t>(k));
        out[0] = c0; out[1] = c1; out[2] = c2;
      }
    }
  }
}

// Adds each pixel's samples minus the environment behind them into `corr`.
void Renderer::Impl::resolve(const cv::Rect& tile, float weight) {
  for (int y = tile.y; y < tile.y + tile.height; ++y) {
    float* c = corr.ptr<float>(y);
    const float* env = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
    for (int x = tile.x; x < tile.x + tile.width; ++x) {
      const std::size_t idx = static_cast<std::size_t>((y - tile.y) * kTile + (x - tile.x)) * static_cast<std::size_t>(M);
      float s0 = 0, s1 = 0, s2 = 0;
      int hits = 0;
      for (int k = 0; k < M; ++k) {
        if (!(depth[idx + static_cast<std::size_t>(k)] > 0)) continue;
        const float* col = color.data() + 3 * (idx + static_cast<std::size_t>(k));
        s0 += col[0]; s1 += col[1]; s2 += col[2];
        ++hits;
      }
      if (!hits) continue;
      const float h = static_cast<float>(hits);
      c[3 * x] += weight * (s0 - h * env[3 * x]);
      c[3 * x + 1] += weight * (s1 - h * env[3 * x + 1]);
      c[3 * x + 2] += weight * (s2 - h * env[3 * x + 2]);
    }
  }
}

}  // namespace epichead::sim
