// TopologyValidator: in constructed ambiguous cases, connectivity and parallelism pick the
// candidate the model's topology supports over a stronger clutter line.
#include <catch2/catch.hpp>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/cao_model.h"
#include "epichead/vision/topology_validator.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

// A unit square face: vertices 0..3 at image positions (100,100), (200,100), (200,200), (100,200).
struct Square {
  CadModel model;
  Eigen::Vector2d px[4] = {{100, 100}, {200, 100}, {200, 200}, {100, 200}};
  Square() {
    RawModel raw;
    raw.vertices = {{0, 0, 0}, {0.1, 0, 0}, {0.1, 0.1, 0}, {0, 0.1, 0}};
    raw.face_loops = {{0, 1, 2, 3}};
    model = *build_model(raw, "square");
  }
  int edge(int va, int vb) const {
    for (int e = 0; e < static_cast<int>(model.edges.size()); ++e) {
      const ModelEdge& m = model.edges[e];
      if ((m.v0 == va && m.v1 == vb) || (m.v0 == vb && m.v1 == va)) return e;
    }
    return -1;
  }
  // A visible feature for edge e whose candidates are the given lines (best RANSAC support first).
  void add(std::vector<LineFeature>& features, int e, std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> lines) const {
    LineFeature& f = features[e];
    f.edge = e;
    f.visible = true;
    f.piece.edge = e;
    f.piece.a_px = px[model.edges[e].v0];
    f.piece.b_px = px[model.edges[e].v1];
    f.piece.s0 = 0;
    f.piece.s1 = 1;
    int support = 40;
    for (const auto& [a, b] : lines) {
      LineCandidate c;
      c.a_px = a;
      c.b_px = b;
      c.support = support--;
      f.result.candidates.push_back(c);
    }
    f.selected = 0;
  }
};

WindowImage image_of(const cv::Mat& bgr) {
  WindowImage image;
  REQUIRE(image.assign(bgr));
  return image;
}

}  // namespace

TEST_CASE("connectivity prefers the candidate that reaches the junction over a stronger clutter line") {
  Square sq;
  cv::Mat img(300, 300, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::rectangle(img, cv::Rect(100, 100, 100, 100), cv::Scalar(200, 200, 200), cv::FILLED);
  // Clutter: a bar left of the square whose right edge (x = 85) is parallel to the left edge but
  // starts 20 px below the corner, so it never reaches the junction.
  cv::rectangle(img, cv::Rect(70, 120, 15, 80), cv::Scalar(230, 230, 230), cv::FILLED);
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.8);
  const WindowImage image = image_of(img);

  std::vector<LineFeature> features(sq.model.edges.size());
  const int left = sq.edge(3, 0), top = sq.edge(0, 1);
  REQUIRE(left >= 0);
  REQUIRE(top >= 0);
  sq.add(features, left, {{{85, 200}, {85, 100}}, {{100, 200}, {100, 100}}});  // clutter first
  sq.add(features, top, {{{100, 100}, {200, 100}}});

  TopologyValidator validator(sq.model);
  ValidationResult out;
  validator.validate(image, features, out);
  CHECK(out.selected[left] == 1);
  CHECK(out.selected[top] == 0);
  CHECK(out.changed == 1);
  CHECK(out.junction_relations >= 1);
  REQUIRE(out.junctions.size() == 1);
  CHECK(out.junctions[0].vertex == 0);
  CHECK((out.junctions[0].px - Eigen::Vector2d(100, 100)).norm() < 1e-6);

  SECTION("without the true line there is no junction vote and RANSAC's best stays") {
    features[left].result.candidates.pop_back();
    validator.validate(image, features, out);
    CHECK(out.selected[left] == 0);
    CHECK(out.junctions.empty());
  }
}

TEST_CASE("parallelism picks the candidate pair at the projected distance and angle") {
  Square sq;
  cv::Mat img(300, 300, CV_8UC3, cv::Scalar(30, 30, 30));
  const WindowImage image = image_of(img);  // parallelism needs no image evidence
  std::vector<LineFeature> features(sq.model.edges.size());
  const int top = sq.edge(0, 1), bottom = sq.edge(2, 3);
  // The whole square moved 5 px right since the projection: the relation still holds.
  sq.add(features, top, {{{105, 100}, {205, 100}}});
  sq.add(features, bottom, {{{205, 215}, {105, 215}}, {{205, 200}, {105, 200}}, {{205, 190}, {105, 195}}});
  TopologyValidator validator(sq.model);
  ValidationResult out;
  validator.validate(image, features, out);
  CHECK(out.parallel_relations == 1);
  CHECK(out.selected[bottom] == 1);
  CHECK(out.votes[bottom] == 1);
  CHECK(out.selected[top] == 0);
}

TEST_CASE("a feature without relations keeps RANSAC's best candidate and invisible ones get none") {
  Square sq;
  cv::Mat img(300, 300, CV_8UC3, cv::Scalar(30, 30, 30));
  const WindowImage image = image_of(img);
  std::vector<LineFeature> features(sq.model.edges.size());
  const int top = sq.edge(0, 1);
  sq.add(features, top, {{{100, 110}, {200, 110}}, {{100, 100}, {200, 100}}});
  TopologyValidator validator(sq.model);
  ValidationResult out;
  validator.validate(image, features, out);
  CHECK(out.selected[top] == 0);
  CHECK(out.relations[top] == 0);
  for (int e = 0; e < static_cast<int>(features.size()); ++e)
    if (e != top) CHECK(out.selected[e] == -1);
}
