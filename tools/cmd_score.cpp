// `epichead score SEQ POSES.csv [--json] [--sym-axis X,Y,Z] [--per-frame FILE.csv]
//  [--reference REF.csv] [--corners FRAME:FILE]...`: scores a tracker's poses against the
// sequence's gt.csv or another tracker's poses (rotation, translation and reprojection errors,
// 5 cm / 5 degree success, losses), and against hand-read corners of single frames (real video).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <expected>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "command.h"
#include "epichead/vision/model_symmetry.h"
#include "line_selection_score.h"
#include "epichead/vision/offline/pose_consistency.h"
#include "epichead/vision/offline/score.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"

namespace epichead::tools {
namespace {

using vision::ErrorStats;
using vision::ScoreSummary;

// "X,Y,Z" -> a unit vector, or the reason it is not one.
std::expected<Eigen::Vector3d, std::string> parse_axis(const std::string& text) {
  std::stringstream in(text);
  std::string part;
  std::vector<double> values;
  while (std::getline(in, part, ',')) {
    try {
      std::size_t used = 0;
      const double v = std::stod(part, &used);
      while (used < part.size() && part[used] == ' ') ++used;
      if (used != part.size() || !std::isfinite(v)) throw std::invalid_argument(part);
      values.push_back(v);
    } catch (const std::exception&) {
      return std::unexpected("--sym-axis '" + text + "': '" + part + "' is not a finite number");
    }
  }
  if (values.size() != 3 || (!text.empty() && text.back() == ','))
    return std::unexpected("--sym-axis '" + text + "': expected three numbers X,Y,Z");
  const Eigen::Vector3d axis(values[0], values[1], values[2]);
  if (axis.norm() < 1e-9) return std::unexpected("--sym-axis '" + text + "': the axis must not be zero");
  return axis.normalized();
}

nlohmann::json stats_json(const ErrorStats& s) {
  // NaN (no frame with an estimate) becomes null in JSON.
  return {{"mean", s.mean}, {"median", s.median}, {"p95", s.p95}};
}

nlohmann::json to_json(const vision::PoseConsistency& c) {
  return {{"dof", c.dof},
          {"count", c.count},
          {"mean", c.mean},
          {"median", c.median},
          {"within_95pct", c.within_95pct},
          {"below_2_5pct", c.below_2_5pct},
          {"above_97_5pct", c.above_97_5pct},
          {"scale_for_mean", c.scale_for_mean}};
}

std::string number_or_empty(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

// With covariances, also each scored frame's NEES (empty where not counted). The error twist
// (truth = exp(error) * estimate, camera frame, metres and radians) says which way a frame is off.
std::expected<void, std::string> write_per_frame(const std::string& path, const ScoreSummary& summary,
                                                 const std::optional<vision::PoseConsistency>& consistency) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) return std::unexpected(path + ": cannot open for writing");
  std::map<int, double> nees;
  if (consistency)
    for (const auto& v : consistency->per_frame) nees[v.frame] = v.nees;
  std::fprintf(f, "frame,present,success,rotation_deg,translation_mm,reprojection_px,"
                  "err_tx_m,err_ty_m,err_tz_m,err_rx_rad,err_ry_rad,err_rz_rad%s\n",
               consistency ? ",nees" : "");
  for (const auto& s : summary.per_frame) {
    std::fprintf(f, "%d,%d,%d,%s,%s,%s", s.frame, s.present ? 1 : 0, s.success ? 1 : 0,
                 number_or_empty(s.rotation_deg).c_str(), number_or_empty(s.translation_mm).c_str(),
                 number_or_empty(s.reprojection_px).c_str());
    for (int i = 0; i < 6; ++i) std::fprintf(f, ",%s", number_or_empty(s.error_twist[i]).c_str());
    if (consistency) {
      const auto it = nees.find(s.frame);
      std::fprintf(f, ",%s", it == nees.end() ? "" : number_or_empty(it->second).c_str());
    }
    std::fprintf(f, "\n");
  }
  if (std::fclose(f) != 0) return std::unexpected(path + ": write error");
  return {};
}

void print_human(const std::string& seq_dir, const ScoreSummary& s, int ignored) {
  std::printf("sequence         %s\n", seq_dir.c_str());
  std::printf("frames           %d (with an estimate: %d, succeeded: %d)\n", s.frames, s.present, s.succeeded);
  std::printf("success rate     %.1f %% (within 50 mm and 5 deg)\n", 100.0 * s.success_rate);
  std::printf("tight success    %.1f %% (within 20 mm and 2 deg)\n", 100.0 * s.success_rate_tight);
  std::printf("losses           %d\n", s.losses);
  if (ignored > 0) std::printf("ignored          %d estimates for frames without ground truth\n", ignored);
  std::printf("%-16s %10s %10s %10s\n", "", "mean", "median", "p95");
  const auto row = [](const char* name, const ErrorStats& e) {
    std::printf("%-16s %10.3f %10.3f %10.3f\n", name, e.mean, e.median, e.p95);
  };
  row("rotation_deg", s.rotation_deg);
  row("translation_mm", s.translation_mm);
  row("reprojection_px", s.reprojection_px);
}

// The frames a simulated sequence's cover board hides the whole object in (sim_truth.json's
// object_hidden_frames, runs [first, last]); empty for a sequence without that file or key.
std::expected<std::set<int>, std::string> hidden_frames(const std::string& seq_dir) {
  const std::string path = seq_dir + "/sim_truth.json";
  std::ifstream in(path);
  std::set<int> hidden;
  if (!in) return hidden;
  try {
    const nlohmann::json j = nlohmann::json::parse(in);
    if (!j.contains("object_hidden_frames")) return hidden;
    for (const auto& run : j.at("object_hidden_frames")) {
      const int first = run.at(0).get<int>(), last = run.at(1).get<int>();
      if (first < 0 || last < first || last - first > 10'000'000)
        return std::unexpected(path + ": object_hidden_frames holds a bad run [" + std::to_string(first) + ", " +
                               std::to_string(last) + "]");
      for (int f = first; f <= last; ++f) hidden.insert(f);
    }
  } catch (const nlohmann::json::exception& e) {
    return std::unexpected(path + ": " + e.what());
  }
  return hidden;
}

// --corners FRAME:FILE...: per frame, the distance of the projected model points from the
// hand-read corners at that frame's estimate (present: false when lost or absent).
std::expected<nlohmann::json, std::string> score_corners(const std::vector<std::string>& specs,
                                                         const std::vector<vision::StampedPose>& estimates,
                                                         const vision::Camera& camera) {
  nlohmann::json out = nlohmann::json::array();
  for (const std::string& spec : specs) {
    const auto colon = spec.find(':');
    int frame = -1;
    try {
      std::size_t used = 0;
      frame = colon == std::string::npos ? -1 : std::stoi(spec.substr(0, colon), &used);
      if (used != colon) frame = -1;
    } catch (const std::exception&) {
      frame = -1;
    }
    if (frame < 0) return std::unexpected("--corners '" + spec + "': expected FRAME:FILE");
    auto points = vision::read_corners(spec.substr(colon + 1));
    if (!points) return std::unexpected(points.error());
    const vision::StampedPose* at = nullptr;
    for (const auto& e : estimates)
      if (e.frame == frame && e.status != "lost") at = &e;
    nlohmann::json c{{"frame", frame}, {"file", spec.substr(colon + 1)}, {"present", at != nullptr}};
    if (at) {
      const vision::CornerError err = vision::corner_error(*points, at->cam_T_obj, camera);
      c["rms_px"] = err.rms_px;
      c["max_px"] = err.max_px;
    }
    out.push_back(c);
  }
  return out;
}

const CommandRegistration registration{
    "score", "Score a tracker's poses against a sequence's ground truth (5 cm / 5 deg success, errors, losses)",
    [](CLI::App& app) {
      auto seq_dir = std::make_shared<std::string>();
      auto poses_path = std::make_shared<std::string>();
      auto json = std::make_shared<bool>(false);
      auto axis_text = std::make_shared<std::string>();
      auto per_frame = std::make_shared<std::string>();
      auto reference = std::make_shared<std::string>();
      auto corners = std::make_shared<std::vector<std::string>>();
      auto lines = std::make_shared<std::string>();
      auto symmetric = std::make_shared<bool>(false);
      auto include_hidden = std::make_shared<bool>(false);
      auto covariance = std::make_shared<std::string>();
      app.add_option("SEQ", *seq_dir, "Sequence directory (with gt.csv)")->required();
      app.add_option("POSES", *poses_path, "Estimated poses: frame,t_s,tx,ty,tz,qw,qx,qy,qz[,status]")->required();
      app.add_flag("--json", *json,
                   "Print one JSON object: frames, present, succeeded, success_rate, success_rate_2cm_2deg, losses, "
                   "rotation_deg/translation_mm/reprojection_px {mean, median, p95}");
      app.add_option("--sym-axis", *axis_text,
                     "X,Y,Z: the object is symmetric about this axis through its origin (object frame); "
                     "the unobservable turn about it is removed before scoring");
      app.add_flag("--include-hidden", *include_hidden,
                   "Also score the frames in which a cover board hides the whole object (sim_truth.json's "
                   "object_hidden_frames); by default they are left out, since nothing can be measured there");
      app.add_flag("--symmetric", *symmetric,
                   "Score up to the model's own symmetries (turns that map its points onto its points, e.g. a box's half "
                   "turns): a pose found without a start (detect) may be any of them");
      app.add_option("--per-frame", *per_frame,
                     "Write frame,present,success,rotation_deg,translation_mm,reprojection_px, the error twist "
                     "(err_tx_m..err_rz_rad: truth = exp(err) * estimate, camera frame) and, with --covariance, "
                     "nees to this CSV");
      app.add_option("--reference", *reference,
                     "Compare with these poses instead of gt.csv (e.g. another tracker's reference_visp.csv)");
      app.add_option("--lines", *lines,
                     "The tracker's lines.csv: also score which image line it selected for each edge against the truth");
      app.add_option("--covariance", *covariance,
                     "The tracker's vision_covariance.csv: also report whether its covariances are honest (the NEES of "
                     "the frames within 5 cm / 5 deg against chi-square, 6 degrees of freedom, 5 with --sym-axis)");
      app.add_option("--corners", *corners,
                     "FRAME:FILE: hand-read corners (X Y Z u v per line) of one frame; reports the distance of the "
                     "projected model points (repeatable)");
      return [=]() -> int {
        std::optional<Eigen::Vector3d> axis;
        if (!axis_text->empty()) {
          auto parsed = parse_axis(*axis_text);
          if (!parsed) return fail("score", parsed.error());
          axis = *parsed;
        }
        auto seq = vision::Sequence::open(*seq_dir);
        if (!seq) return fail("score", seq.error());
        auto estimates = vision::read_pose_csv(*poses_path);
        if (!estimates) return fail("score", estimates.error());

        // Hand-read corners of single frames.
        auto corner_json = score_corners(*corners, *estimates, seq->camera());
        if (!corner_json) return fail("score", corner_json.error());
        std::vector<vision::StampedPose> truth_poses;
        if (!reference->empty()) {
          auto ref = vision::read_pose_csv(*reference);
          if (!ref) return fail("score", ref.error());
          truth_poses = std::move(*ref);
        } else if (seq->has_ground_truth()) {
          truth_poses = seq->ground_truth();
        } else if (corners->empty()) {
          return fail("score", *seq_dir + " has no gt.csv (no ground truth to score against); give --reference or --corners");
        }
        if (truth_poses.empty()) {  // corners only
          if (*json) {
            std::cout << nlohmann::json{{"corners", *corner_json}}.dump() << std::endl;
          } else {
            for (const auto& c : *corner_json)
              std::printf("corners frame %d: %s\n", c["frame"].get<int>(),
                          c["present"].get<bool>() ? (std::to_string(c["rms_px"].get<double>()) + " px rms, " +
                                                      std::to_string(c["max_px"].get<double>()) + " px max").c_str()
                                                   : "no estimate (lost or absent)");
          }
          return 0;
        }

        // Frames a cover board hides the object in are not scored (nothing can be measured
        // there), unless --include-hidden; an estimate that claims to track one is counted.
        std::set<int> hidden;
        int hidden_tracked = 0;
        if (reference->empty() && !*include_hidden) {
          auto read = hidden_frames(*seq_dir);
          if (!read) return fail("score", read.error());
          hidden = std::move(*read);
          std::erase_if(truth_poses, [&](const vision::StampedPose& g) { return hidden.count(g.frame) > 0; });
          for (const auto& e : *estimates) hidden_tracked += hidden.count(e.frame) > 0 && e.status == "tracked";
        }
        const int hidden_count = static_cast<int>(hidden.size());
        const std::vector<Eigen::Isometry3d> symmetries =
            *symmetric ? vision::model_symmetries(seq->model()) : std::vector<Eigen::Isometry3d>{};
        const ScoreSummary summary =
            vision::score_poses(truth_poses, *estimates, seq->camera(), seq->model(), axis, {}, symmetries);
        nlohmann::json line_json = nullptr;
        if (!lines->empty()) {
          auto ls = score_line_selection(*lines, *seq, truth_poses);
          if (!ls) return fail("score", ls.error());
          line_json = to_json(*ls);
        }
        nlohmann::json consistency_json = nullptr;
        std::optional<vision::PoseConsistency> consistency;
        if (!covariance->empty()) {
          auto covs = vision::read_pose_covariance_csv(*covariance);
          if (!covs) return fail("score", covs.error());
          consistency = vision::pose_consistency(summary, *covs);
          consistency_json = to_json(*consistency);
        }
        std::set<int> truth_frames;
        for (const auto& g : truth_poses) truth_frames.insert(g.frame);
        int ignored = 0;
        for (const auto& e : *estimates) ignored += truth_frames.count(e.frame) == 0 && hidden.count(e.frame) == 0;

        if (!per_frame->empty()) {
          if (auto written = write_per_frame(*per_frame, summary, consistency); !written) return fail("score", written.error());
        }
        if (*json) {
          const nlohmann::json j{{"frames", summary.frames},
                                 {"present", summary.present},
                                 {"succeeded", summary.succeeded},
                                 {"success_rate", summary.success_rate},
                                 {"succeeded_2cm_2deg", summary.succeeded_tight},
                                 {"success_rate_2cm_2deg", summary.success_rate_tight},
                                 {"losses", summary.losses},
                                 {"ignored", ignored},
                                 {"hidden_frames", hidden_count},
                                 {"hidden_reported_tracked", hidden_tracked},
                                 {"rotation_deg", stats_json(summary.rotation_deg)},
                                 {"translation_mm", stats_json(summary.translation_mm)},
                                 {"reprojection_px", stats_json(summary.reprojection_px)},
                                 {"against", reference->empty() ? "gt.csv" : *reference},
                                 {"corners", *corner_json},
                                 {"line_selection", line_json},
                                 {"covariance_consistency", consistency_json}};
          std::cout << j.dump() << std::endl;
        } else {
          print_human(*seq_dir, summary, ignored);
          if (hidden_count > 0)
            std::printf("hidden           %d frames with the object behind a cover, not scored (%d reported tracked)\n",
                        hidden_count, hidden_tracked);
          for (const auto& c : *corner_json)
            if (c["present"].get<bool>())
              std::printf("corners frame %d   %.2f px rms, %.2f px max\n", c["frame"].get<int>(), c["rms_px"].get<double>(),
                          c["max_px"].get<double>());
            else
              std::printf("corners frame %d   no estimate (lost or absent)\n", c["frame"].get<int>());
          if (!consistency_json.is_null() && consistency_json["count"].get<int>() == 0)
            std::printf("covariance       no frame within 5 cm / 5 deg has a covariance\n");
          else if (!consistency_json.is_null())
            std::printf("covariance       NEES mean %.2f, median %.2f over %d frames (chi-square %d: mean %d); %.1f %% within "
                        "its 95 %% bounds, %.1f %% above\n",
                        consistency_json["mean"].get<double>(), consistency_json["median"].get<double>(),
                        consistency_json["count"].get<int>(), consistency_json["dof"].get<int>(),
                        consistency_json["dof"].get<int>(), 100 * consistency_json["within_95pct"].get<double>(),
                        100 * consistency_json["above_97_5pct"].get<double>());
          if (!line_json.is_null())
            std::printf("line selection   %.1f %% right of %d; edges with a close parallel neighbour %.1f %% of %d\n",
                        100 * line_json["right_rate"].get<double>(), line_json["selections"].get<int>(),
                        100 * line_json["crowded_right_rate"].get<double>(), line_json["crowded_selections"].get<int>());
        }
        return 0;
      };
    }};

}  // namespace
}  // namespace epichead::tools
