// One frame: the materials at the frame time, the environment at as few instants as its own
// motion needs, the objects at every sub-frame (render_objects.cpp), then gain, gamma, lens
// distortion and noise.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "renderer_impl.h"

namespace epichead::sim {
namespace {

using render::FrameMaterial;
using render::kEncodeSteps;
using render::kEnvStepPx;

// Pose at fraction f (0..1) of the sub-frame sequence, interpolating neighbours.
Eigen::Isometry3d interpolate(std::span<const SubFrame> subs, double f, Eigen::Isometry3d SubFrame::*member) {
  const double s = f * static_cast<double>(subs.size() - 1);
  const std::size_t i = std::min(static_cast<std::size_t>(s), subs.size() - 1);
  const std::size_t j = std::min(i + 1, subs.size() - 1);
  const double a = s - static_cast<double>(i);
  const Eigen::Isometry3d& A = subs[i].*member;
  const Eigen::Isometry3d& B = subs[j].*member;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(A.linear()).slerp(a, Eigen::Quaterniond(B.linear())).toRotationMatrix();
  out.translation() = (1 - a) * A.translation() + a * B.translation();
  return out;
}

}  // namespace

void Renderer::Impl::update_materials(double t_s) {
  for (std::size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    FrameMaterial& f = materials[i];
    const double s = m.change_period_s > 0 ? std::sin(2 * std::numbers::pi * t_s / m.change_period_s + m.change_phase_rad) : 0.0;
    f.albedo = m.albedo_bgr.cwiseMax(0.f).cwiseMin(1.f);
    f.albedo_max = std::max(f.albedo.maxCoeff(), 1e-3f);
    f.time_factor = static_cast<float>(std::max(0.0, 1 + m.change_amplitude * s));
    f.gradient = (m.gradient_per_m_obj * (1 + m.gradient_swing * s)).cast<float>();
    f.gradient_origin = m.gradient_origin_obj.cast<float>();
    f.texture = m.texture;
    f.tex_origin = m.tex_origin_obj.cast<float>();
    f.tex_u = (m.tex_u_obj * m.tex_px_per_m).cast<float>();
    f.tex_v = (m.tex_v_obj * m.tex_px_per_m).cast<float>();
  }
}

// How far (ideal pixels) the environment moves in the image over the exposure: rays through
// a 3x3 grid of the first sub-frame hit the environment (or a point 10 m away), and those
// points are projected in the other sub-frames.
double Renderer::Impl::environment_motion_px(std::span<const SubFrame> subs) const {
  const Eigen::Isometry3d& first = subs.front().world_T_cam;
  double motion = 0;
  for (int gy = 0; gy < 3; ++gy)
    for (int gx = 0; gx < 3; ++gx) {
      const double u = (0.1 + 0.4 * gx) * W, v = (0.1 + 0.4 * gy) * H;
      const Eigen::Vector3d ray_world = first.linear() * Eigen::Vector3d((u - cx) / fx, (v - cy) / fy, 1).normalized();
      double depth_m = 10;
      for (const auto& p : scene.background.planes) {
        const Eigen::Vector3d n = p.world_T_plane.linear().col(2);
        const double denom = n.dot(ray_world);
        if (std::abs(denom) < 1e-9) continue;
        const double d = n.dot(p.world_T_plane.translation() - first.translation()) / denom;
        if (d > 0) depth_m = std::min(depth_m, d);
      }
      const Eigen::Vector3d point = first.translation() + depth_m * ray_world;
      for (const auto& sf : subs.subspan(1)) {
        const Eigen::Vector3d p_cam = sf.world_T_cam.inverse() * point;
        if (p_cam.z() <= 1e-6) return 1e9;
        const double du = fx * p_cam.x() / p_cam.z() + cx - u, dv = fy * p_cam.y() / p_cam.z() + cy - v;
        motion = std::max(motion, std::hypot(du, dv));
      }
    }
  return std::isfinite(motion) ? motion : 1e9;
}

void Renderer::Impl::render(const FrameInput& frame, cv::RNG& rng, cv::Mat& out) {
  out.create(camera.height_px(), camera.width_px(), CV_8UC3);
  const int n_sub = static_cast<int>(frame.sub_frames.size());
  if (n_sub == 0) {
    const cv::Vec3b plain = environment->plain_bgr8();
    out.setTo(cv::Scalar(plain[0], plain[1], plain[2]));
    return;
  }
  update_materials(frame.t_s);
  // The environment is drawn at as many instants as its own motion needs (at most one per
  // sub-frame): consecutive copies at most kEnvStepPx apart blur as smoothly as the bilinear
  // texture lookup can show, and a still background is drawn once.
  const auto subs = frame.sub_frames;
  const double motion = n_sub > 1 ? environment_motion_px(subs) : 0.0;
  const int n_env = std::clamp(1 + static_cast<int>(std::ceil(motion / kEnvStepPx)), 1, n_sub);
  env_instants.resize(static_cast<std::size_t>(n_env));
  for (int j = 0; j < n_env; ++j) {
    const double f = n_env == 1 ? 0.5 : static_cast<double>(j) / (n_env - 1);
    env_instants[static_cast<std::size_t>(j)] = {interpolate(subs, f, &SubFrame::world_T_cam),
                                                 interpolate(subs, f, &SubFrame::world_T_obj)};
  }
  environment->render(env_instants, opt.shadows && scene.shadows.enabled, env_linear.data());
  corr_box = cv::Rect();
  for (int i = 0; i < n_sub; ++i)
    object_pass(subs[static_cast<std::size_t>(i)], i, n_sub, 1.f / static_cast<float>(n_sub));

  // Gain and gamma through a table (pow per pixel would dominate the frame time).
  const float gain = static_cast<float>(std::max(0.0, frame.illumination_gain)) * kEncodeSteps;
  if (corr_box.area() > 0) {
    for (int y = corr_box.y; y < corr_box.y + corr_box.height; ++y) {
      float* a = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
      const float* c = corr.ptr<float>(y);
      for (int i = 3 * corr_box.x; i < 3 * (corr_box.x + corr_box.width); ++i) a[i] += c[i];
    }
  }
  auto encode_row = [&](int y, float* e) {
    const float* a = env_linear.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(W) * 3;
    for (int i = 0; i < 3 * W; ++i) {
      const float f = std::clamp(a[i] * gain, 0.f, static_cast<float>(kEncodeSteps) - 0.01f);
      const int j = std::min(static_cast<int>(f), kEncodeSteps - 1);
      const float r = f - static_cast<float>(j);
      e[i] = encode_lut[static_cast<std::size_t>(j)] * (1 - r) + encode_lut[static_cast<std::size_t>(j) + 1] * r;
    }
  };
  // Noise: a xorshift stream seeded from `rng`, mapped through the Gaussian quantile table.
  std::uint64_t state = (static_cast<std::uint64_t>(static_cast<unsigned>(rng)) << 32) | static_cast<unsigned>(rng);
  state |= 1;
  const float sigma = static_cast<float>(std::max(0.0, opt.noise_sigma_dn));
  auto noise_row = [&](const float* src, uchar* dst, int n) {
    for (int i = 0; i < n; ++i) {
      float val = src[i];
      if (sigma > 0) {
        state ^= state >> 12; state ^= state << 25; state ^= state >> 27;
        const std::uint64_t r = state * 0x2545F4914F6CDD1DULL;
        val += sigma * gauss_table[static_cast<std::size_t>(r >> 48)];
      }
      dst[i] = cv::saturate_cast<uchar>(val);
    }
  };
  if (!distort) {  // one pass, row by row
    for (int y = 0; y < H; ++y) {
      float* e = encoded.ptr<float>(0);
      encode_row(y, e);
      noise_row(e, out.ptr<uchar>(y), 3 * W);
    }
    return;
  }
  for (int y = 0; y < H; ++y) encode_row(y, encoded.ptr<float>(y));
  cv::remap(encoded, remapped, map1, map2, cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  for (int y = 0; y < out.rows; ++y) noise_row(remapped.ptr<float>(y), out.ptr<uchar>(y), 3 * out.cols);
}

}  // namespace epichead::sim
