// The environment layer (textured planes, cast shadows) as the renderer draws it row by row over
// the instants of the exposure: a blurred environment is the average of its still renders, a
// soft shadow keeps the darkness of the hard one and only spreads it, and a built-in scene keeps
// the brightness and sharpness the renderer gave it before the environment was rewritten for
// speed (issue 3).
#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/sim/renderer.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene.h"
#include "epichead/sim/scene_library.h"
#include "epichead/vision/camera.h"

using namespace epichead;

namespace {

const vision::Camera kCamera(640, 480, {800.0, 805.0, 321.3, 238.7});

// A wall 1.2 m in front of the camera (facing it) with a strongly structured texture, nothing else.
sim::Scene wall_scene() {
  sim::Scene s;
  s.name = "test_wall";
  cv::Mat tex(256, 384, CV_8UC3);
  cv::RNG rng(5);
  rng.fill(tex, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(tex, tex, cv::Size(), 1.5);
  s.textures.push_back(tex);
  sim::EnvironmentPlane wall;
  wall.world_T_plane.translation() = Eigen::Vector3d(0, 0, 1.2);
  wall.world_T_plane.linear() = Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitY()).toRotationMatrix();  // +z toward the camera
  wall.width_m = 1.6;
  wall.height_m = 1.2;
  wall.texture = 0;
  s.background.planes.push_back(wall);
  s.background.plain_bgr = {0.2f, 0.3f, 0.4f};
  return s;
}

sim::RenderOptions quiet() {
  sim::RenderOptions o;
  o.noise_sigma_dn = 0;
  return o;
}

cv::Mat render(sim::Renderer& r, const std::vector<sim::SubFrame>& subs) {
  sim::FrameInput f;
  f.sub_frames = subs;
  cv::RNG rng(3);
  return r.render(f, rng);
}

// 8-bit gamma-encoded image -> linear float.
cv::Mat to_linear(const cv::Mat& img, double gamma) {
  cv::Mat f;
  img.convertTo(f, CV_32F, 1.0 / 255);
  cv::pow(f, gamma, f);
  return f;
}

}  // namespace

TEST_CASE("a moving environment renders as the average of its still renders at the sub-frame poses", "[renderer]") {
  sim::Renderer r(wall_scene(), kCamera, quiet());
  // 4 sub-frames, 3 px apart sideways: the environment is drawn at each of them.
  std::vector<sim::SubFrame> subs(4);
  for (std::size_t k = 0; k < subs.size(); ++k)
    subs[k].world_T_cam = Eigen::Isometry3d(Eigen::Translation3d(3.0 * static_cast<double>(k) * 1.2 / 800.0, 0, 0));
  const cv::Mat blurred = render(r, subs);
  cv::Mat mean_linear = cv::Mat::zeros(blurred.size(), CV_32FC3);
  for (const auto& sf : subs) mean_linear += to_linear(render(r, {sf}), 2.2) / static_cast<double>(subs.size());
  cv::Mat expected;
  cv::pow(mean_linear, 1 / 2.2, expected);
  expected.convertTo(expected, CV_8U, 255);
  cv::Mat diff;
  cv::absdiff(blurred, expected, diff);
  const cv::Rect inner(40, 40, 560, 400);  // away from the wall's border
  double max_diff = 0;
  cv::minMaxLoc(diff(inner).reshape(1), nullptr, &max_diff);
  const double mean_diff = cv::mean(diff(inner).reshape(1))[0];
  CAPTURE(max_diff, mean_diff);
  CHECK(mean_diff < 0.3);  // 8-bit rounding of the still renders only
  CHECK(max_diff <= 3);
  // And the blur is real: the moving render differs from any single still one.
  CHECK(cv::norm(blurred(inner), render(r, {subs[0]})(inner), cv::NORM_L1) / inner.area() > 1.0);
}

TEST_CASE("a soft cast shadow removes as much light as the hard one and spreads it over a few pixels", "[renderer]") {
  // A 10 cm cube on a grey floor, lit from the side; a row across the shadow's edge.
  auto scene = [](double softness_px) {
    sim::Scene s;
    s.name = "test_shadow";
    sim::Material m;
    m.albedo_bgr = {0.9f, 0.9f, 0.9f};
    s.materials.push_back(m);
    sim::add_box(s.object_mesh, Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.05)), {0.1, 0.1, 0.1}, 0);
    sim::EnvironmentPlane floor;
    floor.width_m = floor.height_m = 3;
    floor.tint_bgr = {0.6f, 0.6f, 0.6f};
    floor.receives_shadow = true;
    s.background.planes.push_back(floor);
    s.light.direction_world = Eigen::Vector3d(1, 0.2, 1).normalized();
    s.light.ambient = 0.3;
    s.light.diffuse = 0.7;
    s.shadows.enabled = true;
    s.shadows.ground_z_m = 0;
    s.shadows.softness_px = softness_px;
    return s;
  };
  sim::Renderer hard(scene(0.0), kCamera, quiet()), soft(scene(3.0), kCamera, quiet());
  std::vector<sim::SubFrame> subs(1);
  subs[0].world_T_cam = sim::look_at({0, -0.6, 0.5}, {-0.1, 0, 0});
  const cv::Mat a = render(hard, subs), b = render(soft, subs);
  // The shadow falls toward -x: scan the row through the middle of it, left of the cube.
  const Eigen::Vector2d mid = kCamera.project(subs[0].world_T_cam.inverse() * Eigen::Vector3d(-0.12, 0, 0));
  const int row = static_cast<int>(mid.y());
  const int x_cube = static_cast<int>(kCamera.project(subs[0].world_T_cam.inverse() * Eigen::Vector3d(-0.05, 0, 0)).x());
  const int lit = a.at<cv::Vec3b>(row, 5)[1];
  double dark_hard = 0, dark_soft = 0;
  int ramp_hard = 0, ramp_soft = 0, min_hard = 255;
  for (int x = 5; x < x_cube - 8; ++x) {
    const int va = a.at<cv::Vec3b>(row, x)[1], vb = b.at<cv::Vec3b>(row, x)[1];
    dark_hard += lit - va;
    dark_soft += lit - vb;
    min_hard = std::min(min_hard, va);
    ramp_hard += va < lit - 2 && va > min_hard + 2;
    ramp_soft += vb < lit - 2 && vb > min_hard + 2;
  }
  CAPTURE(row, x_cube, lit, min_hard, dark_hard, dark_soft, ramp_hard, ramp_soft);
  REQUIRE(lit - min_hard > 20);                                 // there is a shadow on this row
  CHECK(std::abs(dark_soft - dark_hard) < 0.05 * dark_hard);    // blurring keeps its darkness
  CHECK(ramp_hard <= 2);
  CHECK(ramp_soft >= 4);                                         // a penumbra of a few pixels
  CHECK(ramp_soft <= 16);
}

TEST_CASE("a blurred box_clutter frame keeps the brightness and sharpness of the reference renderer", "[renderer]") {
  // The sim_render_box benchmark's frame without noise. Reference figures: the renderer of
  // commit 1b00932 (before the environment was drawn row by row over all instants): mean BGR
  // 67.909, 105.326, 137.922; mean |d/dx|, |d/dy| (Sobel) 6.9137, 22.100.
  auto scenario = sim::find_scenario("box_clutter");
  REQUIRE(scenario);
  auto scene = sim::make_scene(scenario->scene);
  REQUIRE(scene);
  sim::RenderOptions options = quiet();
  options.samples_per_subframe = scenario->antialias_samples;
  const vision::Camera camera(640, 480, {839.2, 839.4, 325.7, 243.7});
  const Eigen::Isometry3d world_T_cam = sim::look_at(scene->view.camera_world, scene->view.target_world);
  const int n = scenario->blur_subframes.value_or(scene->blur_subframes);
  const double exposure_s = scenario->exposure_s.value_or(scene->exposure_s);
  std::vector<sim::SubFrame> subs(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    const double dt = exposure_s * ((k + 0.5) / n - 0.5);
    subs[static_cast<std::size_t>(k)].world_T_cam =
        world_T_cam * Eigen::Translation3d(0.1 * dt, 0, 0) * Eigen::AngleAxisd(0.35 * dt, Eigen::Vector3d::UnitY());
  }
  sim::Renderer r(std::move(*scene), camera, options);
  sim::FrameInput f;
  f.sub_frames = subs;
  f.t_s = 1.0;
  cv::RNG rng(1);
  const cv::Mat img = r.render(f, rng);
  const cv::Scalar mean = cv::mean(img);
  cv::Mat grey, gx, gy;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  cv::Sobel(grey, gx, CV_32F, 1, 0);
  cv::Sobel(grey, gy, CV_32F, 0, 1);
  const double sharp_x = cv::mean(cv::abs(gx))[0], sharp_y = cv::mean(cv::abs(gy))[0];
  CAPTURE(mean, sharp_x, sharp_y);
  CHECK(std::abs(mean[0] - 67.909) < 0.05);
  CHECK(std::abs(mean[1] - 105.326) < 0.05);
  CHECK(std::abs(mean[2] - 137.922) < 0.05);
  CHECK(std::abs(sharp_x - 6.9137) < 0.01 * 6.9137);
  CHECK(std::abs(sharp_y - 22.100) < 0.01 * 22.100);
}
