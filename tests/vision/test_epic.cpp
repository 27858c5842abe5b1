// EPIC on synthetic windows: cue integration against clutter, adaptation to a lighting ramp,
// sub-pixel accuracy, several candidates for close parallel edges, ObjectSide handling.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "epichead/vision/epic.h"
#include "epichead/vision/line_window.h"
#include "epichead/vision/window_image.h"

using namespace epichead::vision;

namespace {

using Colour = cv::Vec3d;  // B, G, R

// Renders colour(x, y) (pixel centres at integers) with 4x4 supersampling, then a Gaussian blur
// (a camera's optics) and optional Gaussian noise from a fixed seed.
cv::Mat render(int w, int h, const std::function<Colour(double, double)>& colour, double blur_sigma = 1.0,
               double noise_sigma = 0.0, unsigned seed = 1) {
  cv::Mat img(h, w, CV_32FC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      Colour sum(0, 0, 0);
      for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) sum += colour(x - 0.375 + 0.25 * i, y - 0.375 + 0.25 * j);
      img.at<cv::Vec3f>(y, x) = cv::Vec3f(sum / 16.0);
    }
  if (blur_sigma > 0) cv::GaussianBlur(img, img, cv::Size(0, 0), blur_sigma);
  if (noise_sigma > 0) {
    cv::Mat noise(h, w, CV_32FC3);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_sigma);
    img += noise;
  }
  cv::Mat out;
  img.convertTo(out, CV_8UC3);
  return out;
}

// A straight edge through `centre` with unit normal n, blurred by a Gaussian of blur_sigma:
// exactly A + (B - A) Phi(distance / sigma) at each pixel centre, so the edge is where it is
// said to be (a supersampled renderer quantises its position to the sub-sample grid).
cv::Mat render_edge(int w, int h, const Eigen::Vector2d& centre, const Eigen::Vector2d& n, const Colour& inside,
                    const Colour& outside, double blur_sigma) {
  cv::Mat out(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double d = (Eigen::Vector2d(x, y) - centre).dot(n);
      const double t = 0.5 * std::erfc(-d / (blur_sigma * std::sqrt(2.0)));
      const Colour c = outside + (inside - outside) * t;
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<uchar>(c[0]), cv::saturate_cast<uchar>(c[1]),
                                          cv::saturate_cast<uchar>(c[2]));
    }
  return out;
}

// Distance of image point p from the infinite line through a, b.
double line_distance(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = (b - a).normalized();
  return std::abs((p - a).x() * d.y() - (p - a).y() * d.x());
}

// Runs one window: sample, (init references if needed), detect.
struct Runner {
  EpicOptions options;
  LineWindow window;
  EpicDetector detector;
  EpicResult result;
  FeatureReferences refs;
  explicit Runner(const EpicOptions& o = {}) : options(o), detector(o) { result.reserve({}, o.ransac); }
  void run(const cv::Mat& img, const Eigen::Vector2d& a, const Eigen::Vector2d& b, ObjectSide side, EpicMode mode,
           bool look_through = false) {
    WindowImage wi;
    REQUIRE(wi.assign(img).has_value());
    REQUIRE(window.sample(wi, a, b));
    if (!refs.initialised) detector.init_references(window, side, refs);
    detector.detect(window, side, refs, mode, result, look_through);
  }
};

// Object (brown cardboard) for x > 60, grey background, and a strong clutter edge (a white
// object) at x = 52 on the background side. a -> b runs down, so the object is on the Left.
const Colour kObject(60, 100, 140), kBackground(30, 30, 30), kClutter(250, 250, 250);
Colour clutter_scene(double x, double) { return x > 60.0 ? kObject : (x > 52.0 ? kBackground : kClutter); }

}  // namespace

TEST_CASE("EPIC returns the object edge beside a stronger clutter edge, gradient-only the clutter", "[epic]") {
  const cv::Mat img = render(120, 120, clutter_scene, 1.0, 1.5);
  // Prediction 1.5 px off the true edge, between it and the clutter.
  const Eigen::Vector2d a(58.5, 20), b(58.5, 100);
  const Eigen::Vector2d true_a(60, 0), true_b(60, 120), clutter_a(52, 0), clutter_b(52, 120);

  Runner epic;
  epic.run(img, a, b, ObjectSide::Left, EpicMode::Epic);
  REQUIRE(epic.result.found());
  const LineCandidate& e = epic.result.candidates.front();
  CHECK(line_distance(e.a_px, true_a, true_b) < 0.5);
  CHECK(line_distance(e.b_px, true_a, true_b) < 0.5);
  CHECK(e.support >= epic.window.geometry().rows * 3 / 4);

  Runner grad;
  grad.run(img, a, b, ObjectSide::Left, EpicMode::Gradient);
  REQUIRE(grad.result.found());
  CHECK(grad.result.candidates.size() == 1);
  const LineCandidate& g = grad.result.candidates.front();
  CHECK(line_distance(g.a_px, clutter_a, clutter_b) < 0.5);
  CHECK(line_distance(g.b_px, clutter_a, clutter_b) < 0.5);
}

TEST_CASE("the cue likelihood of the object edge beats the clutter edge in every row", "[epic]") {
  const cv::Mat img = render(120, 120, clutter_scene, 1.0, 1.5);
  Runner epic;
  epic.run(img, {60, 20}, {60, 100}, ObjectSide::Left, EpicMode::Epic);
  const auto& set = epic.result.edgels;
  int rows_checked = 0;
  for (int r = 0; r < set.rows; ++r) {
    float object = -1, clutter = -1;
    for (int k = set.row_begin[r]; k < set.row_begin[r + 1]; ++k) {
      const Edgel& e = set.edgels[k];
      if (std::abs(e.x_px - 0.0f) < 1.5f) object = e.likelihood;   // x = 60 is the centre line
      if (std::abs(e.x_px - 8.0f) < 1.5f) clutter = e.likelihood;  // x = 52: columns run toward -x
    }
    if (object < 0 || clutter < 0) continue;
    ++rows_checked;
    CHECK(object > 0.8f);
    CHECK(clutter < 0.5f * object);
  }
  CHECK(rows_checked >= set.rows * 3 / 4);
}

TEST_CASE("references follow a lighting ramp over 100 frames and the edge is kept", "[epic]") {
  // The object brightens from 0.7x to 1.5x of its colour over 100 frames; background and clutter
  // stay. Each frame the window is placed on the previous result (tracking) and the references
  // are updated from the selected candidate.
  struct Outcome { int lost = 0; float mu = 0, sigma = 0, final_likelihood = 0; };
  auto run_ramp = [](float update_rate) {
    EpicOptions opt;
    opt.update_rate = update_rate;
    Runner epic(opt);
    Eigen::Vector2d a(60, 20), b(60, 100);
    Outcome out;
    for (int f = 0; f < 100; ++f) {
      const double gain = 0.7 + 0.8 * f / 99.0;
      const cv::Mat img = render(120, 120, [&](double x, double y) {
        return x > 60.0 ? Colour(kObject * gain) : clutter_scene(x, y);
      }, 1.0, 1.5, 100 + f);
      epic.run(img, a, b, ObjectSide::Left, EpicMode::Epic);
      const bool ok = epic.result.found() && line_distance(epic.result.candidates.front().a_px, {60, 0}, {60, 1}) < 1.0 &&
                      line_distance(epic.result.candidates.front().b_px, {60, 0}, {60, 1}) < 1.0;
      if (!ok) { ++out.lost; continue; }
      const LineCandidate& c = epic.result.candidates.front();
      double sum = 0;
      for (int k = 0; k < c.support; ++k) sum += epic.result.edgels.edgels[epic.result.inliers[c.inlier_begin + k]].likelihood;
      out.final_likelihood = static_cast<float>(sum / c.support);
      epic.detector.update_references(epic.result, c, ObjectSide::Left, epic.refs);
      a = c.a_px;
      b = c.b_px;
    }
    out.mu = epic.refs.side[0].mu[0];
    out.sigma = epic.refs.side[0].sigma[0];
    return out;
  };
  const float truth = static_cast<float>((kObject[0] + kObject[1] + kObject[2]) / 3.0 * 1.5);
  const Outcome adaptive = run_ramp(0.3f);
  CHECK(adaptive.lost == 0);
  CHECK(std::abs(adaptive.mu - truth) < 6.0f);  // lag of the forgetting: ~0.8 levels/frame * (1-a)/a
  CHECK(adaptive.sigma < 10.0f);                // sigma does not blow up (nor collapse: floored)
  CHECK(adaptive.sigma >= 4.0f);
  CHECK(adaptive.final_likelihood > 0.85f);     // all three cues still agree at the end
  // Frozen references: the intensity cue no longer agrees at the end (chromaticity, being
  // illumination-invariant, still does), so the object edge's likelihood drops.
  const Outcome frozen = run_ramp(0.0f);
  CHECK(std::abs(frozen.mu - truth) > 30.0f);
  CHECK(frozen.final_likelihood < 0.75f);
}

TEST_CASE("sub-pixel accuracy is within 0.1 px on a clean blurred edge", "[epic]") {
  for (double angle_deg : {90.0, 75.0, 110.0, 30.0}) {
    const double th = angle_deg * M_PI / 180.0;
    const Eigen::Vector2d d(std::cos(th), std::sin(th)), n(d.y(), -d.x());
    const Eigen::Vector2d centre(80.37, 79.81);
    const cv::Mat img = render_edge(160, 160, centre, n, Colour(40, 120, 200), Colour(200, 190, 180), 1.2);
    for (EpicMode mode : {EpicMode::Gradient, EpicMode::Epic}) {
      Runner r;
      // Predicted 1.3 px off and slightly rotated.
      const Eigen::Vector2d a = centre - 35 * d + 1.3 * n, b = centre + 35 * d + 0.6 * n;
      r.run(img, a, b, ObjectSide::Left, mode);
      INFO("angle " << angle_deg << " mode " << static_cast<int>(mode));
      REQUIRE(r.result.found());
      const LineCandidate& c = r.result.candidates.front();
      CHECK(line_distance(c.a_px, centre, centre + d) < 0.1);
      CHECK(line_distance(c.b_px, centre, centre + d) < 0.1);
    }
  }
}

TEST_CASE("two close parallel edges with equal evidence yield two candidates, epic-single one", "[epic]") {
  // Object side (Left = +x for a->b down) of the edge at x = 64 is 100, of the edge at x = 57 is
  // the 130 stripe: with a reference of 115 +- 20 both are equally likely object edges.
  const cv::Mat img = render(120, 120, [](double x, double) {
    const double v = x > 64 ? 100 : (x > 57 ? 130 : 200);
    return Colour(v, v, v);
  }, 0.8);
  Runner r;
  r.refs.initialised = true;
  r.refs.side[0].mu = {115, 85, 85, 0.5};
  r.refs.side[0].sigma = {20, 4, 4, 4};
  r.run(img, {60.5, 20}, {60.5, 100}, ObjectSide::Left, EpicMode::Epic);
  REQUIRE(r.result.candidates.size() == 2);
  std::vector<double> xs;
  for (const LineCandidate& c : r.result.candidates) {
    CHECK(c.support >= r.window.geometry().rows * 3 / 4);
    CHECK(std::abs(c.a_px.x() - c.b_px.x()) < 0.3);  // vertical
    xs.push_back(0.5 * (c.a_px.x() + c.b_px.x()));
  }
  std::sort(xs.begin(), xs.end());
  CHECK(xs[0] == Approx(57).margin(0.3));
  CHECK(xs[1] == Approx(64).margin(0.3));
  r.detector.detect(r.window, ObjectSide::Left, r.refs, EpicMode::EpicSingle, r.result);
  CHECK(r.result.candidates.size() == 1);
}

TEST_CASE("ObjectSide::Right and Both weigh the intervals on the right side", "[epic]") {
  // Same clutter scene with a->b running up: the object (x > 60) is now on the Right.
  const cv::Mat img = render(120, 120, clutter_scene, 1.0, 1.5);
  Runner right;
  right.run(img, {58.5, 100}, {58.5, 20}, ObjectSide::Right, EpicMode::Epic);
  REQUIRE(right.result.found());
  CHECK(std::abs(right.result.candidates.front().a_px.x() - 60) < 0.5);
  // Told the wrong side, EPIC takes the background for the object: the clutter edge wins.
  Runner wrong;
  wrong.run(img, {58.5, 100}, {58.5, 20}, ObjectSide::Left, EpicMode::Epic);
  REQUIRE(wrong.result.found());
  CHECK(std::abs(wrong.result.candidates.front().a_px.x() - 60) > 3);
  // Both: each side keeps its own reference, so an edge between two faces is found too.
  const cv::Mat faces = render(120, 120, [](double x, double) { return x > 60 ? Colour(40, 80, 160) : Colour(120, 140, 150); }, 1.0, 1.5);
  Runner both;
  both.run(faces, {61.5, 100}, {61.5, 20}, ObjectSide::Both, EpicMode::Epic);
  REQUIRE(both.result.found());
  CHECK(std::abs(both.result.candidates.front().a_px.x() - 60) < 0.5);
  CHECK(both.refs.side[0].mu[0] != Approx(both.refs.side[1].mu[0]).margin(10));
}

TEST_CASE("windows without edges or outside the image give no candidate and do not crash", "[epic]") {
  const cv::Mat flat(100, 100, CV_8UC3, cv::Scalar(90, 90, 90));
  Runner r;
  r.run(flat, {50, 10}, {50, 90}, ObjectSide::Left, EpicMode::Epic);
  CHECK_FALSE(r.result.found());
  CHECK(r.result.edgels.edgels.empty());
  Runner outside;
  outside.run(flat, {-400, -300}, {-400, 900}, ObjectSide::Both, EpicMode::Epic);
  CHECK_FALSE(outside.result.found());
  Runner grad;
  grad.run(flat, {50, 10}, {50, 90}, ObjectSide::Left, EpicMode::Gradient);
  CHECK_FALSE(grad.result.found());
}

TEST_CASE("look-through keeps a contour with a thin printed border, without it EPIC takes the border's inner edge", "[epic]") {
  // A dark face (x > 63) with a 3 px lighter border strip (60 < x < 63) on a light background:
  // the model's contour is x = 60. The contour's edgels have the strip on their object side,
  // emptied by the edge margins, so without look-through they get no evidence (C = 0) and the
  // inner edge of the border (x = 63) wins; with it they see the face beyond the strip too.
  const Colour face(60, 60, 60), strip(130, 130, 130), background(230, 230, 230);
  const cv::Mat img = render(120, 120, [&](double x, double) { return x > 63.0 ? face : (x > 60.0 ? strip : background); },
                             0.7, 1.0);
  const Eigen::Vector2d a(60.5, 20), b(60.5, 100);  // a -> b runs down: the face is on the Left
  const Eigen::Vector2d contour_a(60, 0), contour_b(60, 120), inner_a(63, 0), inner_b(63, 120);
  auto on = [](const LineCandidate& c, const Eigen::Vector2d& p, const Eigen::Vector2d& q) {
    return line_distance(c.a_px, p, q) < 0.7 && line_distance(c.b_px, p, q) < 0.7;
  };
  // Mean likelihood of the edgels near window offset x (columns run toward -x: x = 60 is +0.5).
  auto mean_likelihood = [](const EpicResult& r, float x_px) {
    double sum = 0;
    int n = 0;
    for (const Edgel& e : r.edgels.edgels)
      if (std::abs(e.x_px - x_px) < 1.0f) { sum += e.likelihood; ++n; }
    return n > 0 ? sum / n : -1.0;
  };

  Runner plain;
  plain.run(img, a, b, ObjectSide::Left, EpicMode::Epic, false);
  REQUIRE(plain.result.found());
  CHECK(on(plain.result.candidates.front(), inner_a, inner_b));
  for (const LineCandidate& c : plain.result.candidates) CHECK_FALSE(on(c, contour_a, contour_b));
  CHECK(mean_likelihood(plain.result, 0.5f) < 0.1);

  Runner through;
  through.run(img, a, b, ObjectSide::Left, EpicMode::Epic, true);
  REQUIRE(through.result.found());
  bool contour = false;
  for (const LineCandidate& c : through.result.candidates) contour = contour || on(c, contour_a, contour_b);
  CHECK(contour);
  CHECK(mean_likelihood(through.result, 0.5f) > 0.8);
  CHECK(through.result.look_through);
  // The reference update reads the intervals the likelihood used: the face's, not the strip's.
  const int contour_candidate = [&] {
    for (int k = 0; k < static_cast<int>(through.result.candidates.size()); ++k)
      if (on(through.result.candidates[k], contour_a, contour_b)) return k;
    return 0;
  }();
  FeatureReferences refs = through.refs;
  through.detector.update_references(through.result, through.result.candidates[contour_candidate], ObjectSide::Left, refs);
  CHECK(refs.side[0].mu[static_cast<int>(CueChannel::Intensity)] == Approx(60.0).margin(8.0));
}
