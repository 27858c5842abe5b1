// `epichead detect SEQ --frame N [--imu on] [--near POSES.csv] [--out DIR]`: finds the model's pose in one frame
// from the CAD model and the camera alone (vision/detector.h). Writes DIR/pose.csv (init.csv's
// format: copy it in as the sequence's init.csv), DIR/detection.json (every hypothesis, the
// timings, the template cache) and DIR/detection.png (the found pose drawn over the frame).
// With gt.csv the error of the found pose is printed too (not with --model, another model than
// the sequence's). Exit 0 found, 1 not found or an error, 2 a bad command line.
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command.h"
#include "detection_setup.h"
#include "pose_json.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/offline/overlay.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/visibility.h"

namespace epichead::tools {
namespace {

using namespace epichead::vision;
namespace fs = std::filesystem;

struct DetectArgs {
  std::string seq, out = "detect_out", imu = "off", model, near;
  int frame = 0;
  bool every_hypothesis = false;
  DetectionArgs detection;
};

// Rotation (deg) and translation (mm) between a pose and the ground truth of its frame.
std::optional<std::pair<double, double>> error_to_truth(const Sequence& seq, int frame, const Eigen::Isometry3d& T) {
  for (const auto& g : seq.ground_truth())
    if (g.frame == frame) {
      const double rot = Eigen::AngleAxisd(T.linear() * g.cam_T_obj.linear().transpose()).angle() * 180 / M_PI;
      return std::make_pair(rot, (T.translation() - g.cam_T_obj.translation()).norm() * 1e3);
    }
  return std::nullopt;
}

// Which of the verification's tests a hypothesis failed (vision::failed_detection_tests), each
// with its measure and the limit.
std::string refusal(const vision::DetectionHypothesis& h, const vision::DetectorOptions& o) {
  const unsigned failed = vision::failed_detection_tests(h, o);
  std::string why;
  char part[128];
  const auto add = [&](unsigned test, const char* format, double value, double limit) {
    if (!(failed & test)) return;
    std::snprintf(part, sizeof part, format, value, limit);
    why += (why.empty() ? "" : ", ") + std::string(part);
  };
  add(vision::kTooLittleSupport, "support %.2f below %.2f", h.support, o.min_support);
  add(vision::kTooShortOutline, "supported outline %.0f px below %.0f px", h.supported_px, o.min_supported_px);
  add(vision::kOutlineRunsOn, "its outline runs on %.2f, above %.2f", h.colour_continuation, o.max_colour_continuation);
  add(vision::kUnsupportedEdges, "%.2f of its outline on unsupported edges, above %.2f", h.unsupported_edge_share,
      o.max_unsupported_edge_share);
  return why;
}

int run_detect(const DetectArgs& a) {
  const char* cmd = "detect";
  if (a.imu != "on" && a.imu != "off") return fail(cmd, "--imu must be on or off, got '" + a.imu + "'");
  auto seq = Sequence::open(a.seq);
  if (!seq) return fail(cmd, seq.error());
  if (a.frame < 0 || static_cast<std::size_t>(a.frame) >= seq->frame_count())
    return fail(cmd, "--frame " + std::to_string(a.frame) + " out of range (the sequence has " +
                         std::to_string(seq->frame_count()) + " frames)");
  const auto up_obj = object_up(a.detection);
  if (!up_obj) return fail(cmd, up_obj.error());
  const FrameEntry entry = seq->frames()[static_cast<std::size_t>(a.frame)];
  DetectionPrior prior;
  if (a.imu == "on") {
    if (!seq->has_imu()) return fail(cmd, a.seq + ": --imu on needs imu.csv");
    if (!*up_obj) std::fprintf(stderr, "epichead detect: note: without --object-up the IMU's gravity does not narrow the search\n");
    prior.up_obj = *up_obj;
    prior.up_cam = up_from_imu(seq->imu(), entry.t_s);
    if (!prior.up_cam) std::fprintf(stderr, "epichead detect: note: no IMU sample near frame %d; searching every view\n", entry.frame);
  }
  if (!a.near.empty()) {
    // Re-acquisition's prior: the last pose before the frame that the tracker did not lose.
    auto poses = read_pose_csv(a.near);
    if (!poses) return fail(cmd, poses.error());
    int latest = -1;
    for (const auto& p : *poses)
      if (p.frame < entry.frame && p.frame > latest && p.status != "lost") {
        latest = p.frame;
        prior.near_cam_T_obj = p.cam_T_obj;
      }
    if (!prior.near_cam_T_obj) return fail(cmd, a.near + ": no pose before frame " + std::to_string(entry.frame) + " that is not lost");
  }
  auto image = seq->read_frame(static_cast<std::size_t>(a.frame));
  if (!image) return fail(cmd, image.error());
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec) return fail(cmd, "cannot create " + a.out + ": " + ec.message());

  // Another model than the sequence's: what the detector says when the object in view is not
  // the one it searches for (docs/detection.md, "a wrong object in view").
  std::optional<CadModel> other_model;
  if (!a.model.empty()) {
    auto loaded = load_cao(a.model);
    if (!loaded) return fail(cmd, loaded.error());
    other_model = std::move(*loaded);
  }
  const CadModel& model = other_model ? *other_model : seq->model();
  // gt.csv is the truth of the sequence's model only.
  const auto truth_error = [&](const Eigen::Isometry3d& T) {
    return other_model ? std::nullopt : error_to_truth(*seq, entry.frame, T);
  };
  const ModelTrackerOptions tracking;
  auto detector = make_detector(cmd, model, seq->camera(), a.detection, tracking);
  if (!detector) return fail(cmd, detector.error());
  const auto result = (*detector)->detect(*image, prior);
  if (!result) return fail(cmd, result.error());

  nlohmann::json j;
  j["sequence"] = a.seq;
  j["model"] = a.model.empty() ? (fs::path(a.seq) / "model.cao").string() : a.model;
  j["frame"] = entry.frame;
  j["found"] = result->found;
  j["templates"] = (*detector)->template_count();
  j["templates_matched"] = result->templates_matched;
  j["template_cache"] = (*detector)->cache_path();
  j["templates_from_cache"] = (*detector)->loaded_from_cache();
  j["templates_s"] = (*detector)->build_s();
  j["matches"] = result->matches;
  j["match_ms"] = result->match_ms;
  j["refine_ms"] = result->refine_ms;
  j["near_used"] = prior.near_cam_T_obj.has_value();
  j["gravity_used"] = prior.up_cam.has_value() && prior.up_obj.has_value();
  nlohmann::json hyps = nlohmann::json::array();
  for (const auto& h : result->hypotheses) {
    nlohmann::json e = pose_json(h.cam_T_obj);
    e["support"] = h.support;
    e["score"] = h.score;
    e["supported_px"] = h.supported_px;
    e["colour_continuation"] = h.colour_continuation;
    e["unsupported_edge_share"] = h.unsupported_edge_share;
    e["weakest_edge_support"] = h.weakest_edge_support;
    e["similarity"] = h.similarity;
    e["status"] = to_string(h.status);
    e["start"] = pose_json(h.start_cam_T_obj);
    if (const auto err = truth_error(h.cam_T_obj)) {
      e["rotation_error_deg"] = err->first;
      e["translation_error_mm"] = err->second;
    }
    if (const auto err = truth_error(h.start_cam_T_obj)) {
      e["start_rotation_error_deg"] = err->first;
      e["start_translation_error_mm"] = err->second;
    }
    hyps.push_back(e);
  }
  j["hypotheses"] = hyps;
  if (!result->hypotheses.empty()) j["best"] = hyps.front();
  const std::string json_path = (fs::path(a.out) / "detection.json").string();
  std::ofstream(json_path) << j.dump(2) << "\n";

  // The overlay: the best pose's visible model over the frame, green when found, red when not.
  cv::Mat canvas = image->channels() == 1 ? cv::Mat() : image->clone();
  if (image->channels() == 1) cv::cvtColor(*image, canvas, cv::COLOR_GRAY2BGR);
  if (!result->hypotheses.empty()) {
    VisibleModel visible = compute_visibility(model, seq->camera(), result->best.cam_T_obj, tracking.visibility);
    OverlayStyle style;
    if (!result->found) style.left = style.right = style.both = style.ellipse = cv::Scalar(60, 60, 255);
    style.thickness = 2;
    draw_visible_model(canvas, visible, style);
  }
  // Every hypothesis as its own picture, for seeing why the search chose what it chose.
  if (a.every_hypothesis)
    for (std::size_t i = 0; i < result->hypotheses.size(); ++i) {
      const auto& h = result->hypotheses[i];
      cv::Mat pic;
      if (image->channels() == 1) cv::cvtColor(*image, pic, cv::COLOR_GRAY2BGR);
      else pic = image->clone();
      OverlayStyle start_style;
      start_style.left = start_style.right = start_style.both = start_style.ellipse = cv::Scalar(160, 160, 160);
      draw_visible_model(pic, compute_visibility(model, seq->camera(), h.start_cam_T_obj, tracking.visibility), start_style);
      draw_visible_model(pic, compute_visibility(model, seq->camera(), h.cam_T_obj, tracking.visibility));
      char text[128];
      std::snprintf(text, sizeof text, "hypothesis %zu  support %.2f  runs on %.2f  score %.0f  similarity %.0f  %s", i, h.support,
                    h.colour_continuation, h.score, h.similarity, to_string(h.status));
      cv::putText(pic, text, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
      char name[64];
      std::snprintf(name, sizeof name, "hypothesis_%02zu.png", i);
      if (!cv::imwrite((fs::path(a.out) / name).string(), pic)) return fail(cmd, "cannot write " + (fs::path(a.out) / name).string());
    }
  // Two lines: one is wider than a 640 px frame.
  char caption[96], timing[96];
  std::snprintf(caption, sizeof caption, "frame %d  %s  support %.2f  runs on %.2f", entry.frame,
                result->found ? "found" : "NOT FOUND", result->best.support, result->best.colour_continuation);
  std::snprintf(timing, sizeof timing, "%d hypotheses, %.0f + %.0f ms", static_cast<int>(result->hypotheses.size()),
                result->match_ms, result->refine_ms);
  cv::putText(canvas, caption, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
  cv::putText(canvas, timing, {8, 36}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
  const std::string png_path = (fs::path(a.out) / "detection.png").string();
  if (!cv::imwrite(png_path, canvas)) return fail(cmd, "cannot write " + png_path);

  std::printf("frame %d: %s, support %.2f, %d templates (%s, %.1f s), %d matched, %d matches, %zu hypotheses; "
              "match %.0f ms, refine %.0f ms\n",
              entry.frame, result->found ? "found" : "not found", result->best.support, (*detector)->template_count(),
              (*detector)->loaded_from_cache() ? "cached" : "built", (*detector)->build_s(), result->templates_matched,
              result->matches, result->hypotheses.size(), result->match_ms, result->refine_ms);
  if (const auto err = truth_error(result->best.cam_T_obj))
    std::printf("against gt.csv: %.2f deg, %.1f mm\n", err->first, err->second);
  if (!result->found)
    return fail(cmd, "the object was not found in frame " + std::to_string(entry.frame) + " (best hypothesis: " +
                         refusal(result->best, a.detection.options) + "); see " + png_path);
  const std::string pose_path = (fs::path(a.out) / "pose.csv").string();
  if (auto ok = write_pose_csv(pose_path, {{entry.frame, entry.t_s, result->best.cam_T_obj, ""}}); !ok) return fail(cmd, ok.error());
  std::printf("wrote %s, %s, %s\n", pose_path.c_str(), json_path.c_str(), png_path.c_str());
  return 0;
}

const CommandRegistration registration{
    "detect", "Find the model's pose in one frame without a starting pose (templates from the CAD model)",
    [](CLI::App& app) {
      auto a = std::make_shared<DetectArgs>();
      app.add_option("SEQ", a->seq, "Sequence directory (camera.yaml, model.cao, frames[, imu.csv, gt.csv])")->required();
      app.add_option("--frame", a->frame, "Frame index (0-based position in the sequence)");
      app.add_option("--out", a->out, "Output directory: pose.csv, detection.json, detection.png")->capture_default_str();
      app.add_option("--imu", a->imu, "on: gravity from imu.csv narrows the search (needs --object-up)")->capture_default_str();
      app.add_option("--model", a->model,
                     "Search for this .cao model instead of the sequence's model.cao (e.g. to check that an object "
                     "not in view is reported not found)");
      app.add_option("--near", a->near,
                     "A pose CSV (init.csv's columns, e.g. track's poses.csv): its last pose before the frame that is "
                     "not lost is refined and verified first, as re-acquisition after a loss does; the global search "
                     "runs only when that pose is not verified");
      app.add_flag("--every-hypothesis", a->every_hypothesis,
                   "Also write hypothesis_NN.png: each refined hypothesis (colour) over its template's pose (grey)");
      add_detection_options(app, a->detection);
      return [a]() { return run_detect(*a); };
    }};

}  // namespace
}  // namespace epichead::tools
