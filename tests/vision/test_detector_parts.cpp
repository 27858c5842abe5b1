// The pieces of detection (vision/detector.h) that can be checked without a search: the view
// sphere, the template cache's file format against bad bytes, edge support on drawn outlines,
// the model symmetries that scoring removes, and how the hypotheses' places are shared out.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "edge_drawing.h"
#include "edge_support.h"
#include "hypothesis_places.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/visibility.h"
#include "template_cache.h"
#include "view_sphere.h"

using namespace epichead::vision;
using namespace epichead::vision::detail;

namespace {

CadModel box(double x, double y, double z) {
  RawModel raw;
  raw.vertices = {{0, 0, 0}, {x, 0, 0}, {x, y, 0}, {0, y, 0}, {0, 0, z}, {x, 0, z}, {x, y, z}, {0, y, z}};
  raw.face_loops = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  auto m = build_model(raw, "box");
  REQUIRE(m);
  return *m;
}

Camera camera() { return Camera(640, 480, Intrinsics{600, 600, 320, 240}); }

// A can of 32 facets standing on its bottom (z = 0 to 0.12 m), as the simulator's can.
constexpr double kCanHeight = 0.12;
CadModel can_model() {
  constexpr int kFacets = 32;
  constexpr double kRadius = 0.04;
  RawModel raw;
  for (int ring = 0; ring < 2; ++ring)
    for (int i = 0; i < kFacets; ++i) {
      const double a = 2 * M_PI * (i + 0.5) / kFacets;  // no vertex on the model's x or y axis
      raw.vertices.push_back({kRadius * std::cos(a), kRadius * std::sin(a), ring * kCanHeight});
    }
  std::vector<int> bottom, top;
  for (int i = 0; i < kFacets; ++i) {
    const int j = (i + 1) % kFacets;
    raw.face_loops.push_back({i, j, kFacets + j, kFacets + i});
    bottom.insert(bottom.begin(), i);
    top.push_back(kFacets + i);
  }
  raw.face_loops.push_back(bottom);
  raw.face_loops.push_back(top);
  auto can = build_model(raw, "can");
  REQUIRE(can);
  return *can;
}


Eigen::Isometry3d looking_at_box(double distance_m) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = look_rotation(Eigen::Vector3d(1, -2, 1.5).normalized(), 0.3);
  T.translation() = Eigen::Vector3d(0.02, -0.01, distance_m) - T.linear() * Eigen::Vector3d(0.08, 0.03, 0.04);
  return T;
}

}  // namespace

TEST_CASE("view sphere: 12, 42 and 162 unit directions, evenly spread") {
  CHECK(view_directions(0).size() == 12);
  CHECK(view_directions(1).size() == 42);
  const auto v = view_directions(2);
  REQUIRE(v.size() == 162);
  double nearest_max = 0;
  for (const auto& a : v) {
    CHECK(std::abs(a.norm() - 1) < 1e-12);
    double nearest = 10;
    for (const auto& b : v)
      if (&a != &b) nearest = std::min(nearest, std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
    nearest_max = std::max(nearest_max, nearest);
  }
  CHECK(nearest_max * 180 / M_PI < 20.0);  // no direction further than 20 deg from its neighbour
}

TEST_CASE("look rotation: the camera on the view direction looks at the object, turned by the roll") {
  for (const auto& from : view_directions(1)) {
    const Eigen::Matrix3d R = look_rotation(from, 0.7);
    CHECK((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-12);
    CHECK(std::abs(R.determinant() - 1) < 1e-12);
    // The direction toward the object is the camera's optical axis.
    CHECK((R * -from - Eigen::Vector3d::UnitZ()).norm() < 1e-9);
  }
  const Eigen::Matrix3d a = look_rotation(Eigen::Vector3d(1, 0, 0), 0), b = look_rotation(Eigen::Vector3d(1, 0, 0), 0.5);
  CHECK(std::abs(Eigen::AngleAxisd(b * a.transpose()).angle() - 0.5) < 1e-9);
}

TEST_CASE("template cache: what is written reads back, and truncated, garbled or stale bytes are errors") {
  std::vector<TemplateRecord> records(2);
  records[0].spec = {3, 5, 1, 0.45f, 12.5f, -3.0f};
  records[1].spec = {160, 23, 7, 1.25f, 40.0f, 33.0f};
  for (auto& r : records)
    for (int level = 0; level < 2; ++level) {
      cv::linemod::Template t;
      t.width = 60 >> level;
      t.height = 40 >> level;
      t.pyramid_level = level;
      for (int k = 0; k < 10; ++k) t.features.emplace_back(k * 3 >> level, k * 2 >> level, k % 8);
      r.levels.push_back(t);
    }
  const std::string bytes = encode_template_cache(42, records);
  const auto back = decode_template_cache(bytes, 42, "cache");
  REQUIRE(back);
  REQUIRE(back->size() == 2);
  CHECK((*back)[1].spec.view == 160);
  CHECK((*back)[1].spec.distance_m == 1.25f);
  CHECK((*back)[0].levels[1].features[9].label == 1);
  CHECK(encode_template_cache(42, *back) == bytes);

  CHECK(decode_template_cache(bytes, 43, "cache").error() == "cache: made for another model, camera or options");
  for (std::size_t cut : {std::size_t{3}, std::size_t{20}, bytes.size() / 2, bytes.size() - 1}) {
    CAPTURE(cut);
    CHECK_FALSE(decode_template_cache(bytes.substr(0, cut), 42, "cache"));
  }
  CHECK(decode_template_cache(bytes + "x", 42, "cache").error() == "cache: trailing bytes after the last template");
  std::string bad_label = bytes;
  bad_label[bad_label.size() - 1] = 9;  // the last feature's label: linemod has 8
  CHECK(decode_template_cache(bad_label, 42, "cache").error() == "cache: template 1: feature out of range");
}

TEST_CASE("edge support: a drawn outline supports its own pose fully, a blank image or a shifted pose not") {
  const CadModel model = box(0.165, 0.068, 0.08);
  const Camera cam = camera();
  Visibility visibility(model, cam);
  VisibleModel seen;
  const Eigen::Isometry3d T = looking_at_box(0.5);
  visibility.compute(T, seen);
  const EdgeDrawing drawing = draw_edges(seen, cam, 4);
  REQUIRE_FALSE(drawing.empty);
  cv::Mat grey = cv::Mat::zeros(cam.height_px(), cam.width_px(), CV_8UC1);
  cv::Mat drawn;
  cv::cvtColor(drawing.bgr, drawn, cv::COLOR_BGR2GRAY);
  drawn.copyTo(grey(cv::Rect(drawing.origin, drawn.size())));
  EdgeGradients g;
  g.compute(grey);
  const EdgeSupport at_pose = edge_support(g, seen);
  CHECK(at_pose.share > 0.95);
  CHECK(at_pose.samples > 100);

  Eigen::Isometry3d shifted = T;
  shifted.translation().x() += 0.03;  // ~36 px to the side
  VisibleModel there;
  visibility.compute(shifted, there);
  CHECK(edge_support(g, there).share < 0.3);

  EdgeGradients blank;
  blank.compute(cv::Mat::zeros(cam.height_px(), cam.width_px(), CV_8UC1));
  CHECK(edge_support(blank, seen).share == 0.0);

  // Edge by edge: every edge of the drawn outline is supported; an edge laid where the image is
  // blank is not, and its samples are the share of the outline on unsupported edges.
  CHECK(at_pose.unsupported_edge_share == 0.0);
  CHECK(at_pose.weakest_edge_support > 0.9);
  VisibleModel with_blank_edge = seen;
  REQUIRE_FALSE(seen.edges.empty());
  VisibleEdge lone = seen.edges.front();
  lone.a_px = {40, 20};
  lone.b_px = {240, 20};  // 200 px along the top, where nothing is drawn
  with_blank_edge.edges.push_back(lone);
  const EdgeSupport with_lone = edge_support(g, with_blank_edge);
  const long lone_samples = with_lone.samples - at_pose.samples;
  CHECK(lone_samples > 60);
  CHECK(with_lone.unsupported_edge_share == Approx(static_cast<double>(lone_samples) / with_lone.samples));
  CHECK(with_lone.weakest_edge_support == 0.0);
  // A short edge (under min_edge_samples) is counted in the share but not judged alone.
  VisibleModel with_short_edge = seen;
  lone.b_px = {60, 20};
  with_short_edge.edges.push_back(lone);
  CHECK(edge_support(g, with_short_edge).unsupported_edge_share == 0.0);
}

TEST_CASE("colour continuation: across the outline's lines the colours differ along the object and stop differing past it") {
  const CadModel model = box(0.165, 0.068, 0.08);
  const Camera cam = camera();
  Visibility visibility(model, cam);
  VisibleModel seen;
  visibility.compute(looking_at_box(0.5), seen);
  REQUIRE(seen.edges.size() >= 6);
  std::vector<cv::Point> corners, hull;
  for (const auto& e : seen.edges) {
    corners.emplace_back(static_cast<int>(std::lround(e.a_px.x())), static_cast<int>(std::lround(e.a_px.y())));
    corners.emplace_back(static_cast<int>(std::lround(e.b_px.x())), static_cast<int>(std::lround(e.b_px.y())));
  }
  cv::convexHull(corners, hull);

  // A pale object on a noisy green background (clutter whose edges are everywhere).
  cv::RNG rng(7);
  cv::Mat scene(cam.height_px(), cam.width_px(), CV_8UC3);
  rng.fill(scene, cv::RNG::UNIFORM, cv::Scalar(20, 90, 20), cv::Scalar(90, 200, 90));
  cv::Mat object(scene.size(), CV_8UC3);
  rng.fill(object, cv::RNG::UNIFORM, cv::Scalar(200, 200, 200), cv::Scalar(250, 250, 250));
  cv::Mat mask = cv::Mat::zeros(scene.size(), CV_8UC1);
  cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  object.copyTo(scene, mask);
  const ColourContinuation alone = colour_continuation(scene, seen);
  CHECK(alone.ends >= 6);
  CHECK(alone.ratio < 0.2);

  // A facade the outline lies on: every edge's line is a colour boundary across the image.
  cv::Mat facade(scene.size(), CV_8UC3);
  for (int y = 0; y < facade.rows; ++y)
    for (int x = 0; x < facade.cols; ++x) {
      cv::Vec3i c(30, 30, 30);
      for (std::size_t i = 0; i < seen.edges.size(); ++i) {
        const auto& e = seen.edges[i];
        const Eigen::Vector2d d = e.b_px - e.a_px, q = Eigen::Vector2d(x, y) - e.a_px;
        if (d.x() * q.y() - d.y() * q.x() > 0) c[static_cast<int>(i % 3)] += 35;
      }
      facade.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]), cv::saturate_cast<uchar>(c[2]));
    }
  const ColourContinuation running_on = colour_continuation(facade, seen);
  CHECK(running_on.ends == alone.ends);  // which ends count depends on the pose alone
  CHECK(running_on.ratio > 0.8);

  // Not a colour frame, or nothing drawn: no ratio, no ends.
  CHECK(colour_continuation(cv::Mat(), seen).ends == 0);
  CHECK(colour_continuation(scene, VisibleModel{}).ends == 0);
}

TEST_CASE("model symmetries: a box of three different sides has three half turns, a wedge none") {
  const auto turns = model_symmetries(box(0.165, 0.068, 0.08));
  REQUIRE(turns.size() == 3);
  for (const auto& S : turns) CHECK(std::abs(Eigen::AngleAxisd(S.linear()).angle() - M_PI) < 1e-9);
  RawModel wedge;
  wedge.vertices = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.05, 0}, {0, 0, 0.02}, {0.1, 0, 0.02}, {0, 0.05, 0.02}};
  wedge.face_loops = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}};
  auto w = build_model(wedge, "wedge");
  REQUIRE(w);
  CHECK(model_symmetries(*w).empty());
}

TEST_CASE("model symmetries: a can of 32 facets has the half turn that swaps its ends, though its cross-section's axes are any two") {
  // The two rings' variance is the same in every direction across the axis, so the principal
  // axes there are whatever the solver gives; the half turn is about a line through a vertex.
  const CadModel can = can_model();
  const auto turns = model_symmetries(can);
  int swaps = 0;
  for (const auto& S : turns) {
    // Every symmetry maps the bottom's centre onto a centre.
    const Eigen::Vector3d c = S * Eigen::Vector3d::Zero();
    CHECK(std::hypot(c.x(), c.y()) < 1e-9);
    if (std::abs(c.z() - kCanHeight) < 1e-9) {
      ++swaps;
      CHECK(std::abs(Eigen::AngleAxisd(S.linear()).angle() - M_PI) < 1e-9);
      CHECK(std::abs((S.linear() * Eigen::Vector3d::UnitZ()).z() + 1) < 1e-9);
    }
  }
  CHECK(swaps >= 1);
}

TEST_CASE("of a pose and its symmetric equivalents, the prior chooses: the turn nearest a prior pose, or the one upright") {
  const CadModel can = can_model();
  const auto turns = model_symmetries(can);
  // The can seen from 0.5 m, a little from above; the found pose is the upside-down equivalent.
  Eigen::Isometry3d truth = Eigen::Translation3d(0.01, 0.02, 0.5) * Eigen::AngleAxisd(-1.9, Eigen::Vector3d::UnitX());
  const auto swap = std::find_if(turns.begin(), turns.end(), [](const Eigen::Isometry3d& S) {
    return (S.linear() * Eigen::Vector3d::UnitZ()).z() < -0.5;
  });
  REQUIRE(swap != turns.end());
  const Eigen::Isometry3d flip = *swap;
  const Eigen::Isometry3d found = truth * flip;
  const auto turn_deg = [](const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
    return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180 / M_PI;
  };
  REQUIRE(turn_deg(found, truth) > 170);
  // Both draw the same points.
  for (const auto& v : can.vertices) {
    const Eigen::Vector3d p = found * v;
    CHECK(std::any_of(can.vertices.begin(), can.vertices.end(), [&](const Eigen::Vector3d& w) { return (truth * w - p).norm() < 1e-9; }));
  }
  // A prediction 10 deg and 2 cm off the truth chooses the truth's turn.
  const Eigen::Isometry3d predicted = Eigen::Translation3d(0.02, 0, 0) * truth * Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d chosen = symmetric_nearest(found, turns, predicted);
  CHECK(turn_deg(chosen, truth) < 1e-6);
  CHECK((chosen.translation() - truth.translation()).norm() < 1e-9);
  CHECK(turn_deg(symmetric_nearest(truth, turns, predicted), truth) < 1e-6);  // already the nearest: kept
  // Gravity: the world's up in the camera frame is the truth's up (its model z); upright wins.
  const Eigen::Vector3d up_cam = truth.linear() * Eigen::Vector3d::UnitZ();
  const Eigen::Isometry3d upright = symmetric_upright(found, turns, Eigen::Vector3d::UnitZ(), up_cam);
  CHECK((upright.linear() * Eigen::Vector3d::UnitZ()).dot(up_cam) == Approx(1.0));
  CHECK((upright * Eigen::Vector3d::Zero() - truth * Eigen::Vector3d::Zero()).norm() < 1e-9);  // bottom where it is
  // No symmetries: the pose as found.
  CHECK(turn_deg(symmetric_nearest(found, {}, predicted), found) < 1e-9);
}

TEST_CASE("hypothesis places are shared out over the distances, what one leaves goes to the best of the rest") {
  // Best first: ten at distance 0 (long outlines on dense texture), then the object's at
  // distance 3. Eight places over four distances: two each at first.
  std::vector<int> distance_of(10, 0);
  distance_of.push_back(3);
  const auto none_lie = [](std::size_t) { return false; };
  const auto kept = hypothesis_places(distance_of, 4, 8, none_lie);
  CHECK(kept == std::vector<std::size_t>{0, 1, 10, 2, 3, 4, 5, 6});  // the object's kept; the rest refilled best first
  // Without the share (one distance), the object's would not be kept.
  const auto unshared = hypothesis_places(std::vector<int>(11, 0), 1, 8, none_lie);
  CHECK(std::find(unshared.begin(), unshared.end(), std::size_t{10}) == unshared.end());
  // A candidate lying on a kept one takes no place, and is not asked about again.
  int asked_about_1 = 0;
  const auto deduped = hypothesis_places(distance_of, 4, 3, [&](std::size_t i) {
    if (i == 1) ++asked_about_1;
    return i == 1;
  });
  CHECK(deduped == std::vector<std::size_t>{0, 10, 2});  // one place per distance at first, then 1 (lies on 0) is passed over
  CHECK(asked_about_1 == 1);
  CHECK(hypothesis_places(distance_of, 4, 0, none_lie).empty());
  CHECK(hypothesis_places({}, 4, 8, none_lie).empty());
}

TEST_CASE("symmetric turn: the turn between two poses as far as an outline can tell, a twin's none, a body of revolution's axis only") {
  const auto turns = model_symmetries(box(0.165, 0.068, 0.08));
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(-1.9, Eigen::Vector3d::UnitX()) * Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())).toRotationMatrix();
  const Eigen::Matrix3d turned20 = R * Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  CHECK(symmetric_turn_rad(R, turned20, turns) * 180 / M_PI == Approx(20).margin(1e-9));
  // A box's half-turn twin draws the same outline: no turn between them.
  REQUIRE_FALSE(turns.empty());
  const Eigen::Matrix3d twin = R * turns.front().linear();
  CHECK(Eigen::AngleAxisd(R.transpose() * twin).angle() * 180 / M_PI > 170);
  CHECK(symmetric_turn_rad(R, twin, turns) < 1e-9);
  CHECK(symmetric_turn_rad(R, twin, {}) * 180 / M_PI > 170);  // without its symmetries it is a half turn
  // A can's turn about its axis (its model z) is no outline's to tell; a tilt of the axis is.
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  const Eigen::Matrix3d about_axis = R * Eigen::AngleAxisd(1.0, axis).toRotationMatrix();
  CHECK(symmetric_turn_rad(R, about_axis, {}, axis) < 1e-9);
  const Eigen::Matrix3d tilted = R * Eigen::AngleAxisd(15 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  CHECK(symmetric_turn_rad(R, tilted, {}, axis) * 180 / M_PI == Approx(15).margin(1e-9));
}
