// `epichead track-lines SEQ --out DIR [--mode gradient|epic|epic-single] [--every N]`: tracks every
// visible model line and circle of a sequence from its previous result (no pose estimation: the
// model is projected once at the init.csv pose and only re-projected for a feature that was
// lost), and writes DIR/lines.csv (one row per frame and visible edge), DIR/ellipses.csv (one row
// per frame and visible circle) and overlays DIR/overlay_NNNNNN.png.
#include <CLI/CLI.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command.h"
#include "epichead/vision/ellipse_tracker.h"
#include "epichead/vision/line_tracker.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/visibility.h"
#include "epichead/vision/window_image.h"

namespace epichead::tools {
namespace {

using namespace epichead::vision;

cv::Point2d pt(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

// Draws, per visible feature: the window outline (grey; red when lost), the good edgels (cyan),
// the other candidates (yellow) and the selected line (green).
void draw_features(cv::Mat& canvas, const LineTracker& tracker) {
  constexpr int shift = 4;  // sub-pixel drawing: coordinates in 1/16 px
  auto P = [](const Eigen::Vector2d& p) { return cv::Point(cvRound(p.x() * 16), cvRound(p.y() * 16)); };
  for (const LineFeature& f : tracker.features()) {
    if (!f.visible) continue;
    const WindowGeometry& g = f.result.geometry;
    const double x0 = g.x_of_col(0), x1 = g.x_of_col(g.cols - 1), s0 = g.s_of_row(0), s1 = g.s_of_row(g.rows - 1);
    const cv::Point quad[4] = {P(g.to_image(x0, s0)), P(g.to_image(x1, s0)), P(g.to_image(x1, s1)), P(g.to_image(x0, s1))};
    cv::polylines(canvas, std::vector<cv::Point>(quad, quad + 4), true, f.found ? cv::Scalar(150, 150, 150) : cv::Scalar(0, 0, 255), 1, cv::LINE_AA, shift);
    for (int k : f.result.good) {
      const Edgel& e = f.result.edgels.edgels[k];
      cv::circle(canvas, P(g.to_image(e.x_px, e.s_px)), 16, {255, 255, 0}, cv::FILLED, cv::LINE_AA, shift);
    }
    for (int c = static_cast<int>(f.result.candidates.size()) - 1; c >= 0; --c) {
      const LineCandidate& cand = f.result.candidates[c];
      const bool selected = c == f.selected;
      cv::line(canvas, P(cand.a_px), P(cand.b_px), selected ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 220, 255),
               selected ? 2 : 1, cv::LINE_AA, shift);
    }
    const Eigen::Vector2d mid = 0.5 * (f.window_a_px + f.window_b_px);
    cv::putText(canvas, std::to_string(f.edge), pt(mid + 22 * g.across), cv::FONT_HERSHEY_PLAIN, 0.8, {255, 255, 255}, 1, cv::LINE_AA);
  }
}

// Draws, per visible circle: the tracker lines across the contour (grey on the arc, orange the
// two extension lines beyond an arc's ends, red a line without an inlier), the good edgels
// (cyan), the other candidates (yellow), the selected ellipse (thin green) and the arc it was
// found on (thick green; magenta when weak, under 180 deg).
void draw_ellipses(cv::Mat& canvas, const EllipseTracker& tracker) {
  constexpr int shift = 4;
  auto P = [](const Eigen::Vector2d& p) { return cv::Point(cvRound(p.x() * 16), cvRound(p.y() * 16)); };
  const double half = 0.5 * (tracker.options().width_px - 1);
  auto draw_ellipse = [&](const Ellipse& e, double from_t, double span_t, const cv::Scalar& colour, int thickness) {
    constexpr int steps = 96;
    std::vector<cv::Point> pts;
    for (int k = 0; k <= steps; ++k) pts.push_back(P(e.point(from_t + span_t * k / steps)));
    cv::polylines(canvas, pts, false, colour, thickness, cv::LINE_AA, shift);
  };
  for (const EllipseFeature& f : tracker.features()) {
    if (!f.visible) continue;
    for (int r = 0; r < static_cast<int>(f.lines.size()); ++r) {
      const TrackerLine& l = f.lines[r];
      const bool extension = r < f.arc_row_begin || r >= f.arc_row_end;
      const bool hit = r < static_cast<int>(f.row_hit.size()) && f.row_hit[r];
      const cv::Scalar colour = extension ? cv::Scalar(0, 140, 255) : hit ? cv::Scalar(150, 150, 150) : cv::Scalar(0, 0, 255);
      cv::line(canvas, P(l.centre_px - half * l.normal), P(l.centre_px + half * l.normal), colour, 1, cv::LINE_AA, shift);
    }
    for (int k : f.result.good) cv::circle(canvas, P(tracker.edgel_px(f, k)), 16, {255, 255, 0}, cv::FILLED, cv::LINE_AA, shift);
    for (int c = 0; c < static_cast<int>(f.candidates.size()); ++c)
      if (c != f.selected) draw_ellipse(f.candidates[c].ellipse, 0, 2 * M_PI, {0, 220, 255}, 1);
    if (!f.found) continue;
    draw_ellipse(f.ellipse, 0, 2 * M_PI, {0, 255, 0}, 1);
    const double t0 = f.ellipse.param_of_polar(f.arc.begin_rad);
    double span = 2 * M_PI;
    if (!f.arc.full()) {
      span = f.ellipse.param_of_polar(f.arc.begin_rad + f.arc.span_rad) - t0;
      span -= 2 * M_PI * std::floor(span / (2 * M_PI));
    }
    draw_ellipse(f.ellipse, t0, span, f.weak ? cv::Scalar(255, 0, 255) : cv::Scalar(0, 255, 0), 3);
    cv::putText(canvas, "c" + std::to_string(f.circle), pt(f.ellipse.centre_px), cv::FONT_HERSHEY_PLAIN, 0.8, {255, 255, 255}, 1,
                cv::LINE_AA);
  }
}

// One row of ellipses.csv for a visible circle.
std::string ellipse_row(int frame_number, const EllipseFeature& f) {
  char buf[256];
  int hit = 0;
  for (unsigned char h : f.row_hit) hit += h;
  if (f.found) {
    const Ellipse& e = f.ellipse;
    std::snprintf(buf, sizeof buf, "%d,%d,1,%zu,%.3f,%.3f,%.3f,%.3f,%.2f,%.1f,%.1f,%d,%d,%d,%zu,%zu\n", frame_number,
                  f.circle, f.candidates.size(), e.centre_px.x(), e.centre_px.y(), e.semi_major_px, e.semi_minor_px,
                  e.angle_rad * 180 / M_PI, f.arc.begin_rad * 180 / M_PI, std::min(f.arc.span_rad, 2 * M_PI) * 180 / M_PI,
                  f.weak ? 1 : 0, f.inlier_count(), hit, f.lines.size(), f.result.good.size());
  } else {
    std::snprintf(buf, sizeof buf, "%d,%d,0,%zu,,,,,,,,0,0,%d,%zu,%zu\n", frame_number, f.circle, f.candidates.size(), hit,
                  f.lines.size(), f.result.good.size());
  }
  return buf;
}

int run_track_lines(const std::string& seq_dir, const std::string& out_dir, const std::string& mode_name, int every,
                    double crease_deg, const std::string& rim_side_name) {
  const char* cmd = "track-lines";
  static const std::map<std::string, EpicMode> modes{
      {"gradient", EpicMode::Gradient}, {"epic", EpicMode::Epic}, {"epic-single", EpicMode::EpicSingle}};
  const auto mode = modes.find(mode_name);
  if (mode == modes.end()) return fail(cmd, "--mode must be gradient, epic or epic-single, got '" + mode_name + "'");
  static const std::map<std::string, RimSide> rim_sides{
      {"inside", RimSide::Inside}, {"outside", RimSide::Outside}, {"both", RimSide::Both}};
  const auto rim_side = rim_sides.find(rim_side_name);
  if (rim_side == rim_sides.end())
    return fail(cmd, "--rim-side must be inside, outside or both, got '" + rim_side_name + "'");
  auto seq = Sequence::open(seq_dir);
  if (seq && !seq->has_init()) return fail(cmd, seq_dir + "/init.csv: missing (track-lines starts from it; `epichead detect` finds one)");
  if (!seq) return fail(cmd, seq.error());
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) return fail(cmd, "cannot create " + out_dir + ": " + ec.message());
  const std::string csv_path = (std::filesystem::path(out_dir) / "lines.csv").string();
  std::ofstream csv(csv_path);
  if (!csv) return fail(cmd, "cannot write " + csv_path);
  csv << "frame,edge,found,candidates,x0,y0,x1,y1,support,good_edgels\n";
  const std::string ellipse_csv_path = (std::filesystem::path(out_dir) / "ellipses.csv").string();
  std::ofstream ellipse_csv(ellipse_csv_path);
  if (!ellipse_csv) return fail(cmd, "cannot write " + ellipse_csv_path);
  ellipse_csv << "frame,circle,found,candidates,cx,cy,a,b,angle_deg,arc_begin_deg,arc_span_deg,weak,support,"
                 "lines_hit,lines,good_edgels\n";

  VisibilityOptions vis_options;
  vis_options.crease_angle_rad = crease_deg * M_PI / 180.0;
  Visibility visibility(seq->model(), seq->camera(), vis_options);
  VisibleModel visible;
  visibility.compute(seq->init().cam_T_obj, visible);  // fixed: tracking goes on from the results

  LineTrackerOptions options;
  options.mode = mode->second;
  LineTracker tracker(options);
  EllipseTrackerOptions ellipse_options;
  ellipse_options.mode = mode->second;
  ellipse_options.side = rim_side->second;
  EllipseTracker ellipses(ellipse_options);
  long long ellipses_placed = 0, ellipses_found = 0, ellipses_on_arc = 0;
  WindowImage image;
  long long found = 0, placed = 0;
  double track_s = 0;
  int overlays = 0;
  const std::size_t n = seq->frame_count();
  for (std::size_t i = 0; i < n; ++i) {
    auto frame = seq->read_frame(i);
    if (!frame) return fail(cmd, frame.error());
    if (auto ok = image.assign(*frame); !ok) return fail(cmd, "frame " + std::to_string(i) + ": " + ok.error());
    const auto t0 = std::chrono::steady_clock::now();
    tracker.track(image, visible, WindowPlacement::Previous);
    ellipses.track(image, visible, WindowPlacement::Previous);
    track_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const int frame_number = seq->frames()[i].frame;
    char buf[256];
    for (const LineFeature& f : tracker.features()) {
      if (!f.visible) continue;
      ++placed;
      found += f.found;
      const int ncand = static_cast<int>(f.result.candidates.size());
      if (f.found) {
        const LineCandidate& c = f.result.candidates[f.selected];
        std::snprintf(buf, sizeof buf, "%d,%d,1,%d,%.3f,%.3f,%.3f,%.3f,%d,%zu\n", frame_number, f.edge, ncand, c.a_px.x(),
                      c.a_px.y(), c.b_px.x(), c.b_px.y(), c.support, f.result.good.size());
      } else {
        std::snprintf(buf, sizeof buf, "%d,%d,0,%d,,,,,0,%zu\n", frame_number, f.edge, ncand, f.result.good.size());
      }
      csv << buf;
    }
    for (const EllipseFeature& f : ellipses.features()) {
      if (!f.visible) continue;
      ++ellipses_placed;
      ellipses_found += f.found;
      ellipses_on_arc += f.found && !f.arc.full();
      ellipse_csv << ellipse_row(frame_number, f);
    }
    if (every > 0 && (i % static_cast<std::size_t>(every) == 0 || i + 1 == n)) {
      cv::Mat canvas;
      if (frame->channels() == 1) cv::cvtColor(*frame, canvas, cv::COLOR_GRAY2BGR);
      else if (frame->channels() == 4) cv::cvtColor(*frame, canvas, cv::COLOR_BGRA2BGR);
      else canvas = frame->clone();
      draw_features(canvas, tracker);
      draw_ellipses(canvas, ellipses);
      const std::string caption = "frame " + std::to_string(frame_number) + "  mode " + mode_name +
                                  "  window grey (red: lost), good edgels cyan, candidates yellow, selected green";
      cv::putText(canvas, caption, {8, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 255, 255}, 1, cv::LINE_AA);
      if (ellipses_placed > 0)
        cv::putText(canvas, "tracker lines grey (red: missed, orange: beyond arc ends), found arc thick green (magenta: weak)",
                    {8, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 255, 255}, 1, cv::LINE_AA);
      std::snprintf(buf, sizeof buf, "overlay_%06d.png", frame_number);
      const std::string path = (std::filesystem::path(out_dir) / buf).string();
      try {
        if (!cv::imwrite(path, canvas)) return fail(cmd, "cannot write " + path);
      } catch (const cv::Exception& e) {
        return fail(cmd, "cannot write " + path + ": " + e.what());
      }
      ++overlays;
    }
  }
  if (!csv.flush()) return fail(cmd, "cannot write " + csv_path);
  if (!ellipse_csv.flush()) return fail(cmd, "cannot write " + ellipse_csv_path);
  std::printf("%zu frames, %lld line windows, %.1f%% found; %lld ellipses, %.1f%% found (%lld on an arc); %.3f ms tracking "
              "per frame; wrote %s, %s and %d overlays\n",
              n, placed, placed ? 100.0 * static_cast<double>(found) / static_cast<double>(placed) : 0.0, ellipses_placed,
              ellipses_placed ? 100.0 * static_cast<double>(ellipses_found) / static_cast<double>(ellipses_placed) : 0.0,
              ellipses_on_arc, n ? 1e3 * track_s / static_cast<double>(n) : 0.0, csv_path.c_str(), ellipse_csv_path.c_str(),
              overlays);
  return 0;
}

const CommandRegistration registration{
    "track-lines", "Track every visible model line and circle from its previous result (EPIC or gradient-only) and write CSV + overlays",
    [](CLI::App& app) {
      auto seq = std::make_shared<std::string>();
      auto out = std::make_shared<std::string>();
      auto mode = std::make_shared<std::string>("epic");
      auto every = std::make_shared<int>(10);
      auto crease_deg = std::make_shared<double>(20.0);
      auto rim_side = std::make_shared<std::string>("inside");
      app.add_option("SEQ", *seq, "Sequence directory")->required();
      app.add_option("--out", *out, "Output directory (lines.csv, ellipses.csv, overlay_NNNNNN.png)")->required();
      app.add_option("--mode", *mode, "gradient (nearest strong gradient), epic (cues, several candidates) or epic-single");
      app.add_option("--every", *every, "Write an overlay every N frames and at the last frame (0: none)")
          ->check(CLI::Range(0, 1000000));
      app.add_option("--crease-deg", *crease_deg, "Crease angle of the visibility test")->check(CLI::Range(0.0, 180.0));
      app.add_option("--rim-side", *rim_side,
                     "Where the object is relative to a projected circle: inside (disc, rim seen with its surface "
                     "inside), outside (hole) or both");
      return [=]() { return run_track_lines(*seq, *out, *mode, *every, *crease_deg, *rim_side); };
    }};

}  // namespace
}  // namespace epichead::tools
