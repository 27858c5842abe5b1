// The renderer draws what the camera model says: edges where Camera::project puts them (with
// and without lens distortion), hidden faces hidden, motion blur along the motion, the same
// bytes for the same seed, light gain and shadows where they belong.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "epichead/sim/renderer.h"
#include "epichead/sim/scene.h"
#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"

using namespace epichead;

namespace {

const Eigen::Vector3d kBoxSize(0.20, 0.15, 0.10);

vision::CadModel box_model() {
  vision::RawModel raw;
  const Eigen::Vector3d h = kBoxSize / 2;
  for (int i = 0; i < 8; ++i) raw.vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(), (i & 4) ? h.z() : -h.z());
  auto v = [](int x, int y, int z) { return x + 2 * y + 4 * z; };
  raw.face_loops = {{v(1, 0, 0), v(1, 1, 0), v(1, 1, 1), v(1, 0, 1)}, {v(0, 1, 0), v(0, 0, 0), v(0, 0, 1), v(0, 1, 1)},
                    {v(1, 1, 0), v(0, 1, 0), v(0, 1, 1), v(1, 1, 1)}, {v(0, 0, 0), v(1, 0, 0), v(1, 0, 1), v(0, 0, 1)},
                    {v(0, 0, 1), v(1, 0, 1), v(1, 1, 1), v(0, 1, 1)}, {v(0, 1, 0), v(1, 1, 0), v(1, 0, 0), v(0, 0, 0)}};
  auto model = vision::build_model(raw, "box");
  REQUIRE(model);
  return *model;
}

// A box centred at the world origin; every face flat `face_bgr[i]` (unlit: ambient 1), over a
// plain black background, no shadows.
sim::Scene box_scene(const std::vector<sim::ColorBgr>& face_bgr) {
  sim::Scene s;
  s.name = "test_box";
  s.model = box_model();
  std::vector<int> face_material;
  for (const auto& c : face_bgr) {
    sim::Material m;
    m.albedo_bgr = c;
    s.materials.push_back(m);
    face_material.push_back(static_cast<int>(s.materials.size()) - 1);
  }
  s.object_mesh = sim::mesh_from_model(s.model, face_material);
  s.background.plain_bgr = {0, 0, 0};
  s.light.ambient = 1.0;
  s.light.diffuse = 0.0;
  s.shadows.enabled = false;
  return s;
}

sim::RenderOptions exact_options() {
  sim::RenderOptions o;
  o.gamma = 1.0;          // pixel value = coverage * 255: edge positions read off linearly
  o.noise_sigma_dn = 0.0;
  return o;
}

vision::Camera camera(bool distorted) {
  const vision::Intrinsics k{800.0, 805.0, 321.3, 238.7};
  if (!distorted) return vision::Camera(640, 480, k);
  return vision::Camera(640, 480, k, {-0.28, 0.09, 0.0012, -0.0008, 0.0});
}

// Renders with `n` sub-frames at the same pose (distinct sample positions: 4 n per pixel).
cv::Mat render_static(sim::Renderer& r, const Eigen::Isometry3d& world_T_cam, int n = 4) {
  std::vector<sim::SubFrame> subs(static_cast<std::size_t>(n));
  for (auto& sf : subs) sf.world_T_cam = world_T_cam;
  sim::FrameInput f;
  f.sub_frames = subs;
  cv::RNG rng(7);
  return r.render(f, rng);
}

// Grey level as coverage 0..1 (white object on black).
double coverage(const cv::Mat& img, int row, int col) {
  const cv::Vec3b p = img.at<cv::Vec3b>(row, col);
  return (p[0] + p[1] + p[2]) / (3 * 255.0);
}

// Camera looking at the box's -y face (front) from `distance_m`, rolled so no edge is axis-aligned.
Eigen::Isometry3d front_view(double distance_m, double roll_rad) {
  Eigen::Isometry3d world_T_cam = sim::look_at({0.004, -distance_m, 0.003}, {0.004, 0, 0.003});
  world_T_cam.linear() = world_T_cam.linear() * Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return world_T_cam;
}

// Where the projection of the 3D segment a-b crosses image row `row` (bisection on the segment;
// the projected curve is monotonic in y for the near-vertical edges used here).
std::optional<double> crossing_x(const vision::Camera& cam, const Eigen::Isometry3d& cam_T_world,
                                 const Eigen::Vector3d& a, const Eigen::Vector3d& b, double row) {
  auto y_at = [&](double s) { return cam.project(cam_T_world * (a + s * (b - a))).y(); };
  double lo = 0, hi = 1;
  if ((y_at(lo) - row) * (y_at(hi) - row) > 0) return std::nullopt;
  const bool rising = y_at(hi) > y_at(lo);
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    ((y_at(mid) < row) == rising ? lo : hi) = mid;
  }
  return cam.project(cam_T_world * (a + 0.5 * (lo + hi) * (b - a))).x();
}

// Edge position along a row from the coverage profile in [x0, x1] (object on one side).
double measured_edge_x(const cv::Mat& img, int row, int x0, int x1) {
  const bool object_left = coverage(img, row, x0) > coverage(img, row, x1);
  double sum = 0;
  for (int x = x0; x <= x1; ++x) sum += object_left ? coverage(img, row, x) : 1 - coverage(img, row, x);
  return x0 - 0.5 + sum;
}

struct EdgeError { double mean = 0, max = 0; int rows = 0; };

// Compares measured and projected positions of a near-vertical 3D edge on every row it crosses
// (away from its ends, where the neighbouring edges interfere).
EdgeError check_vertical_edge(const cv::Mat& img, const vision::Camera& cam, const Eigen::Isometry3d& cam_T_world,
                              const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double ya = cam.project(cam_T_world * a).y(), yb = cam.project(cam_T_world * b).y();
  EdgeError e;
  const int r0 = static_cast<int>(std::ceil(std::min(ya, yb) + 8)), r1 = static_cast<int>(std::floor(std::max(ya, yb) - 8));
  for (int row = r0; row <= r1; ++row) {
    const auto x = crossing_x(cam, cam_T_world, a, b, row);
    if (!x) continue;
    const int xc = static_cast<int>(std::lround(*x));
    if (xc - 6 < 0 || xc + 6 >= img.cols) continue;
    const double d = std::abs(measured_edge_x(img, row, xc - 6, xc + 6) - *x);
    e.mean += d;
    e.max = std::max(e.max, d);
    ++e.rows;
  }
  if (e.rows) e.mean /= e.rows;
  return e;
}

}  // namespace

TEST_CASE("rendered silhouette edges lie where Camera::project puts them, to a fraction of a pixel", "[renderer]") {
  for (bool distorted : {false, true}) {
    CAPTURE(distorted);
    const vision::Camera cam = camera(distorted);
    sim::Renderer r(box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(1, 1, 1))), cam, exact_options());
    // Front face only (the others face away), rolled 12 degrees, off-centre so distortion bends it.
    const Eigen::Isometry3d world_T_cam = front_view(0.45, 12 * std::numbers::pi / 180) *
                                          Eigen::Translation3d(distorted ? 0.025 : 0.0, 0, 0);
    const cv::Mat img = render_static(r, world_T_cam);
    const Eigen::Isometry3d cam_T_world = world_T_cam.inverse();
    const Eigen::Vector3d h = kBoxSize / 2;
    // The front face's two near-vertical edges (x = -h, x = +h on the y = -h face).
    for (double sx : {-1.0, 1.0}) {
      const EdgeError e = check_vertical_edge(img, cam, cam_T_world, {sx * h.x(), -h.y(), -h.z()}, {sx * h.x(), -h.y(), h.z()});
      CAPTURE(sx, e.mean, e.max, e.rows);
      REQUIRE(e.rows > 40);
      CHECK(e.mean < 0.08);
      CHECK(e.max < 0.2);
    }
  }
}

TEST_CASE("a rendered box corner, found from the image edges, is within 0.3 px of its projection", "[renderer]") {
  for (bool distorted : {false, true}) {
    CAPTURE(distorted);
    const vision::Camera cam = camera(distorted);
    sim::Renderer r(box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(1, 1, 1))), cam, exact_options());
    const Eigen::Isometry3d world_T_cam = front_view(0.45, 20 * std::numbers::pi / 180);
    const cv::Mat img = render_static(r, world_T_cam);
    const Eigen::Isometry3d cam_T_world = world_T_cam.inverse();
    const Eigen::Vector3d h = kBoxSize / 2;
    const Eigen::Vector3d corner(-h.x(), -h.y(), h.z());
    const Eigen::Vector2d truth = cam.project(cam_T_world * corner);
    // Measure the two edges meeting at the corner on rows / columns 10..60 px away, fit
    // quadratics (distortion bends them) and intersect.
    const Eigen::Vector2d down = cam.project(cam_T_world * Eigen::Vector3d(-h.x(), -h.y(), -h.z())) - truth;
    const Eigen::Vector2d side = cam.project(cam_T_world * Eigen::Vector3d(h.x(), -h.y(), h.z())) - truth;
    // Near-vertical edge: x(y) along rows; near-horizontal edge: y(x) along columns.
    auto fit = [](const std::vector<Eigen::Vector2d>& pts) {  // v = c0 + c1 t + c2 t^2 from (t, v)
      Eigen::MatrixXd A(static_cast<Eigen::Index>(pts.size()), 3);
      Eigen::VectorXd b(static_cast<Eigen::Index>(pts.size()));
      for (std::size_t i = 0; i < pts.size(); ++i) {
        A.row(static_cast<Eigen::Index>(i)) << 1, pts[i].x(), pts[i].x() * pts[i].x();
        b(static_cast<Eigen::Index>(i)) = pts[i].y();
      }
      return Eigen::Vector3d(A.colPivHouseholderQr().solve(b));
    };
    std::vector<Eigen::Vector2d> vert, horiz;  // (row, x) and (col, y)
    const double dir_y = down.y() > 0 ? 1 : -1, dir_x = side.x() > 0 ? 1 : -1;
    for (int d = 10; d <= 60; ++d) {
      const int row = static_cast<int>(std::lround(truth.y() + dir_y * d));
      const double x_guess = truth.x() + down.x() / down.y() * (row - truth.y());
      const int xc = static_cast<int>(std::lround(x_guess));
      vert.emplace_back(row, measured_edge_x(img, row, xc - 6, xc + 6));
      const int col = static_cast<int>(std::lround(truth.x() + dir_x * d));
      const double y_guess = truth.y() + side.y() / side.x() * (col - truth.x());
      const int yc = static_cast<int>(std::lround(y_guess));
      // Column profile: transpose the idea of measured_edge_x.
      const bool object_top = coverage(img, yc - 6, col) > coverage(img, yc + 6, col);
      double sum = 0;
      for (int y = yc - 6; y <= yc + 6; ++y) sum += object_top ? coverage(img, y, col) : 1 - coverage(img, y, col);
      horiz.emplace_back(col, yc - 6 - 0.5 + sum);
    }
    const Eigen::Vector3d cv_ = fit(vert), ch = fit(horiz);
    Eigen::Vector2d p = truth;  // fixed point: x = fv(y), y = fh(x)
    for (int i = 0; i < 50; ++i) {
      p.x() = cv_(0) + cv_(1) * p.y() + cv_(2) * p.y() * p.y();
      p.y() = ch(0) + ch(1) * p.x() + ch(2) * p.x() * p.x();
    }
    CAPTURE(truth.transpose(), p.transpose());
    CHECK((p - truth).norm() < 0.3);
  }
}

TEST_CASE("faces hidden behind the object do not show in the image", "[renderer]") {
  // Distinct saturated colours: front faces mix only with each other and the black background.
  const std::vector<sim::ColorBgr> colours = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {1, 0, 1}, {0, 1, 1}};
  const vision::Camera cam = camera(false);
  sim::Renderer r(box_scene(colours), cam, exact_options());
  // From the (+x, -y, +z) octant: +x (0), -y (3) and +z (4) face the camera.
  const Eigen::Isometry3d world_T_cam = sim::look_at({0.3, -0.35, 0.25}, Eigen::Vector3d::Zero());
  const cv::Mat img = render_static(r, world_T_cam);
  auto count_near = [&](const sim::ColorBgr& c) {
    int n = 0;
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) {
        const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
        if (std::abs(p[0] - 255 * c[0]) + std::abs(p[1] - 255 * c[1]) + std::abs(p[2] - 255 * c[2]) < 40) ++n;
      }
    return n;
  };
  for (int f : {0, 3, 4}) CHECK(count_near(colours[static_cast<std::size_t>(f)]) > 2000);
  // Hidden faces: -x (1) green, +y (2) red, -z (5) yellow.
  for (int f : {1, 2, 5}) CHECK(count_near(colours[static_cast<std::size_t>(f)]) == 0);
}

TEST_CASE("motion blur widens an edge along the motion and not across it", "[renderer]") {
  const vision::Camera cam = camera(false);
  sim::Renderer r(box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(1, 1, 1))), cam, exact_options());
  const Eigen::Isometry3d base = front_view(0.45, 0.0);
  // 8 px of sideways motion during the exposure (camera x axis), over 6 sub-frames.
  const double motion_m = 8.0 / 800.0 * 0.4;
  std::vector<sim::SubFrame> subs(6);
  for (std::size_t k = 0; k < subs.size(); ++k)
    subs[k].world_T_cam = base * Eigen::Translation3d(motion_m * (static_cast<double>(k) / 5.0 - 0.5), 0, 0);
  sim::FrameInput moving;
  moving.sub_frames = subs;
  cv::RNG rng(1);
  const cv::Mat blurred = r.render(moving, rng);
  const cv::Mat sharp = render_static(r, base, 6);
  const Eigen::Vector2d centre = cam.project(base.inverse() * Eigen::Vector3d(0, -kBoxSize.y() / 2, 0));
  const int cx = static_cast<int>(centre.x()), cy = static_cast<int>(centre.y());
  // Pixels strictly between background and object along a row (vertical edges) and a column.
  auto ramp_row = [&](const cv::Mat& img) {
    int n = 0;
    for (int x = 0; x < img.cols; ++x) n += coverage(img, cy, x) > 0.02 && coverage(img, cy, x) < 0.98;
    return n;
  };
  auto ramp_col = [&](const cv::Mat& img) {
    int n = 0;
    for (int y = 0; y < img.rows; ++y) n += coverage(img, y, cx) > 0.02 && coverage(img, y, cx) < 0.98;
    return n;
  };
  CAPTURE(ramp_row(sharp), ramp_row(blurred), ramp_col(sharp), ramp_col(blurred));
  CHECK(ramp_row(sharp) <= 4);                     // two edges, at most two pixels each
  CHECK(ramp_row(blurred) >= 12);                  // two edges, ~7 px each
  CHECK(ramp_col(blurred) <= ramp_col(sharp) + 1); // vertical direction unchanged
}

TEST_CASE("the same seed gives the same bytes, another seed other noise", "[renderer]") {
  sim::RenderOptions o;
  o.noise_sigma_dn = 3.0;
  sim::Scene s = box_scene({{0.2f, 0.5f, 0.8f}, {0.3f, 0.3f, 0.3f}, {0.6f, 0.2f, 0.1f}, {0.9f, 0.9f, 0.9f}, {0.1f, 0.7f, 0.2f}, {0.5f, 0.5f, 0.1f}});
  s.light.ambient = 0.4;
  s.light.diffuse = 0.6;
  sim::Renderer r(s, camera(true), o);
  const Eigen::Isometry3d pose = sim::look_at({0.3, -0.35, 0.25}, Eigen::Vector3d::Zero());
  std::vector<sim::SubFrame> subs(3);
  for (std::size_t k = 0; k < subs.size(); ++k) subs[k].world_T_cam = pose * Eigen::Translation3d(0.002 * static_cast<double>(k), 0, 0);
  sim::FrameInput f;
  f.sub_frames = subs;
  cv::RNG a(42), b(42), c(43);
  const cv::Mat ia = r.render(f, a), ib = r.render(f, b), ic = r.render(f, c);
  CHECK(cv::norm(ia, ib, cv::NORM_INF) == 0);
  CHECK(cv::norm(ia, ic, cv::NORM_INF) > 0);
  // A second renderer (fresh buffers) agrees byte for byte.
  sim::Renderer r2(s, camera(true), o);
  cv::RNG d(42);
  CHECK(cv::norm(ia, r2.render(f, d), cv::NORM_INF) == 0);
}

TEST_CASE("illumination gain and time-varying reflectance scale the object's radiance", "[renderer]") {
  sim::Scene s = box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(0.4f, 0.4f, 0.4f)));
  for (auto& m : s.materials) {
    m.change_amplitude = 0.5;
    m.change_period_s = 4.0;  // sin = 1 at t = 1 s, 0 at t = 0
  }
  const vision::Camera cam = camera(false);
  sim::Renderer r(s, cam, exact_options());
  const Eigen::Isometry3d pose = front_view(0.45, 0.0);
  const Eigen::Vector2d c = cam.project(pose.inverse() * Eigen::Vector3d(0, -kBoxSize.y() / 2, 0));
  std::vector<sim::SubFrame> subs(1);
  subs[0].world_T_cam = pose;
  auto value = [&](double t, double gain) {
    sim::FrameInput f;
    f.sub_frames = subs;
    f.t_s = t;
    f.illumination_gain = gain;
    cv::RNG rng(1);
    return r.render(f, rng).at<cv::Vec3b>(static_cast<int>(c.y()), static_cast<int>(c.x()))[1];
  };
  CHECK(std::abs(value(0, 1) - 0.4 * 255) <= 1);
  CHECK(std::abs(value(0, 0.5) - 0.2 * 255) <= 1);
  CHECK(std::abs(value(1, 1) - 0.6 * 255) <= 1);
}

TEST_CASE("the object's cast shadow darkens the floor beside it, and only with shadows on", "[renderer]") {
  sim::Scene s = box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(0.8f, 0.8f, 0.8f)));
  // Floor under the box (z = -h), lit steeply from +x so the shadow falls toward -x.
  s.light.direction_world = Eigen::Vector3d(1, 0, 1).normalized();
  s.light.ambient = 0.4;
  s.light.diffuse = 0.6;
  sim::EnvironmentPlane floor;
  floor.world_T_plane.translation() = Eigen::Vector3d(0, 0, -kBoxSize.z() / 2);
  floor.width_m = floor.height_m = 2;
  floor.tint_bgr = {0.5f, 0.5f, 0.5f};
  floor.receives_shadow = true;
  s.background.planes.push_back(floor);
  s.shadows.enabled = true;
  s.shadows.ground_z_m = -kBoxSize.z() / 2;
  const vision::Camera cam = camera(false);
  const Eigen::Isometry3d pose = sim::look_at({0, -0.5, 0.4}, {-0.08, 0, -0.05});
  // A floor point in the shadow (just left of the box) and one in the light (right of it).
  const Eigen::Vector3d shadowed(-0.14, 0, -kBoxSize.z() / 2), lit(0.16, 0, -kBoxSize.z() / 2);
  auto grey_at = [&](const cv::Mat& img, const Eigen::Vector3d& p) {
    const Eigen::Vector2d px = cam.project(pose.inverse() * p);
    return static_cast<int>(img.at<cv::Vec3b>(static_cast<int>(px.y()), static_cast<int>(px.x()))[1]);
  };
  sim::Renderer with(s, cam, exact_options());
  sim::RenderOptions off = exact_options();
  off.shadows = false;
  sim::Renderer without(s, cam, off);
  const cv::Mat a = render_static(with, pose, 1), b = render_static(without, pose, 1);
  CAPTURE(grey_at(a, shadowed), grey_at(b, shadowed), grey_at(a, lit));
  // Shadowed floor keeps the ambient share: 0.4 / (0.4 + 0.6 cos 45deg) of its radiance.
  const double keep = 0.4 / (0.4 + 0.6 * std::sqrt(0.5));
  CHECK(std::abs(grey_at(a, shadowed) - keep * 0.5 * 255) <= 2);
  CHECK(std::abs(grey_at(b, shadowed) - 0.5 * 255) <= 1);
  CHECK(std::abs(grey_at(a, lit) - 0.5 * 255) <= 1);
}

TEST_CASE("an occluder is drawn in front of the object where the caller poses it", "[renderer]") {
  sim::Scene s = box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(1, 1, 1)));
  sim::Material arm;
  arm.albedo_bgr = {0, 0, 1};
  s.materials.push_back(arm);
  sim::Mesh bar;
  sim::add_box(bar, Eigen::Isometry3d::Identity(), {0.02, 0.02, 0.4}, static_cast<int>(s.materials.size()) - 1);
  s.occluders.push_back(bar);
  const vision::Camera cam = camera(false);
  sim::Renderer r(s, cam, exact_options());
  const Eigen::Isometry3d pose = front_view(0.45, 0.0);
  const Eigen::Isometry3d world_T_bar(Eigen::Translation3d(0.0, -0.2, 0.0));  // between camera and box
  std::vector<sim::SubFrame> subs(1);
  subs[0].world_T_cam = pose;
  subs[0].world_T_occluders = std::span<const Eigen::Isometry3d>(&world_T_bar, 1);
  sim::FrameInput f;
  f.sub_frames = subs;
  cv::RNG rng(1);
  const cv::Mat with_arm = r.render(f, rng);
  const Eigen::Vector2d c = cam.project(pose.inverse() * Eigen::Vector3d(0, -kBoxSize.y() / 2, 0));
  const cv::Vec3b p = with_arm.at<cv::Vec3b>(static_cast<int>(c.y()), static_cast<int>(c.x()));
  CHECK(p[2] == 255);
  CHECK(p[0] == 0);
  subs[0].world_T_occluders = {};
  const cv::Vec3b q = r.render(f, rng).at<cv::Vec3b>(static_cast<int>(c.y()), static_cast<int>(c.x()));
  CHECK(q[0] == 255);
}

TEST_CASE("geometry crossing the near plane or behind the camera does not crash or smear", "[renderer]") {
  const vision::Camera cam = camera(true);
  sim::Renderer r(box_scene(std::vector<sim::ColorBgr>(6, sim::ColorBgr(1, 1, 1))), cam, exact_options());
  // Camera inside the box, then just behind it, then a pose full of NaN.
  for (const Eigen::Isometry3d& pose : {sim::look_at({0, 0, 0}, {0, 1, 0}), sim::look_at({0, 0.3, 0}, {0, 1, 0})}) {
    const cv::Mat img = render_static(r, pose, 2);
    CHECK(img.rows == 480);
  }
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  const cv::Mat img = render_static(r, bad, 2);
  CHECK(cv::countNonZero(img.reshape(1)) == 0);  // nothing drawn over the black background
}
