// `epichead-visp SEQ --out DIR [--mode edges|edges+klt] [--overlay-every N]`: runs ViSP's
// model-based tracker (vpMbGenericTracker) on a sequence directory, starting from init.csv, and
// writes poses.csv, report.json and overlays in the same form as epichead's own tracker, so that
// `epichead score` and docs/results.md treat both alike. A separate program (not an `epichead`
// command) because ViSP is optional: it is built only when libvisp-dev is installed.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <expected>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include <opencv2/core/utility.hpp>

#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "overlay.h"
#include "run_report.h"
#include "undistorter.h"
#include "visp_tracker.h"

namespace epichead::visp_compare {
namespace {

std::expected<TrackerMode, std::string> parse_mode(const std::string& text) {
  if (text == "edges") return TrackerMode::edges;
  if (text == "edges+klt") return TrackerMode::edges_klt;
  return std::unexpected("--mode '" + text + "': expected edges or edges+klt");
}

int fail(const std::string& reason) {
  std::cerr << "epichead-visp: " << reason << "\n";
  return 2;
}

struct Options {
  std::string seq_dir;
  std::string out_dir;
  std::string mode = "edges";
  int overlay_every = 0;
};

std::string overlay_path(const std::string& out_dir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "overlay_%06d.png", frame);
  return (std::filesystem::path(out_dir) / name).string();
}

int run(const Options& options) {
  const auto mode = parse_mode(options.mode);
  if (!mode) return fail(mode.error());
  if (options.overlay_every < 0) return fail("--overlay-every must be 0 (none) or positive");
  // One core, as epichead's own tracker is measured (OpenCV's thread pool serves remap and
  // ViSP's KLT; ViSP's OpenMP is limited in VispTracker).
  cv::setNumThreads(1);
  auto seq = vision::Sequence::open(options.seq_dir);
  if (!seq) return fail(seq.error());
  if (!seq->has_init()) return fail(options.seq_dir + "/init.csv: missing (ViSP's tracker starts from it)");
  std::error_code ec;
  std::filesystem::create_directories(options.out_dir, ec);
  if (ec) return fail(options.out_dir + ": cannot create: " + ec.message());

  // Tracking starts at init.csv's frame; earlier frames (if any) are not part of the run.
  const auto& frames = seq->frames();
  std::size_t first = frames.size();
  for (std::size_t i = 0; i < frames.size(); ++i)
    if (frames[i].frame == seq->init().frame) { first = i; break; }
  if (first == frames.size())
    return fail(options.seq_dir + "/init.csv: frame " + std::to_string(seq->init().frame) +
                " is not among the sequence's frames");

  const vision::Camera& camera = seq->camera();
  const TrackerSettings settings = settings_for_image(camera.width_px(), camera.height_px());
  Undistorter undistorter(camera);
  const vision::Intrinsics k = undistorter.pinhole();
  std::string error;
  auto tracker = VispTracker::create((std::filesystem::path(options.seq_dir) / "model.cao").string(),
                                     {k.fx_px, k.fy_px, k.cx_px, k.cy_px}, *mode, settings, error);
  if (!tracker) return fail(error);
  if (options.overlay_every > 0) tracker->keep_display_features();
  OverlayWriter overlay(seq->model(), camera);

  cv::Mat grey;
  std::vector<DisplayFeature> features;
  std::vector<FrameRecord> records;
  std::vector<vision::StampedPose> poses;
  records.reserve(frames.size() - first);
  poses.reserve(frames.size() - first);
  int unreadable = 0;
  for (std::size_t i = first; i < frames.size(); ++i) {
    const int frame_number = frames[i].frame;
    FrameRecord record{frame_number, {}};
    auto frame = seq->read_frame(i);
    std::expected<void, std::string> prepared =
        frame ? undistorter.to_grey_undistorted(*frame, grey) : std::unexpected(frame.error());
    if (prepared) {
      if (i == first) {
        if (const std::string problem = tracker->init(grey, seq->init().cam_T_obj); !problem.empty())
          return fail(options.seq_dir + ": frame " + std::to_string(frame_number) + ": " + problem);
      }
      record.result = tracker->track(grey);
    } else {
      // A frame we cannot read is counted as lost; the tracker goes on with the next one.
      ++unreadable;
      if (i == first) return fail(options.seq_dir + ": frame " + std::to_string(frame_number) + ": " + prepared.error());
      std::cerr << "epichead-visp: frame " << frame_number << ": " << prepared.error() << " (counted as lost)\n";
      record.result.reason = "unreadable frame: " + prepared.error();
      record.result.cam_T_obj = poses.back().cam_T_obj;
    }
    const bool tracked = record.result.status == FrameStatus::tracked;
    poses.push_back({frame_number, frames[i].t_s, record.result.cam_T_obj, tracked ? "tracked" : "lost"});
    if (prepared && options.overlay_every > 0 && (i - first) % static_cast<std::size_t>(options.overlay_every) == 0) {
      tracker->display_features(features);
      if (auto written = overlay.write(overlay_path(options.out_dir, frame_number), *frame, frame_number,
                                       record.result, features, undistorter);
          !written)
        return fail(written.error());
    }
    records.push_back(std::move(record));
  }

  const std::string poses_path = (std::filesystem::path(options.out_dir) / "poses.csv").string();
  if (auto written = vision::write_pose_csv(poses_path, poses); !written) return fail(written.error());
  const std::string report_path = (std::filesystem::path(options.out_dir) / "report.json").string();
  if (auto written = write_report(report_path, options.seq_dir, *mode, settings, records, tracker->reinitialisations());
      !written)
    return fail(written.error());

  int tracked = 0;
  std::vector<double> track_ms, track_cpu_ms;
  for (const auto& r : records) {
    tracked += r.result.status == FrameStatus::tracked;
    track_ms.push_back(r.result.track_ms);
    track_cpu_ms.push_back(r.result.track_cpu_ms);
  }
  std::printf("ViSP %s on %s: %zu frames, %d tracked, %zu lost (%d unreadable), %u re-initialisations, "
              "track %.2f ms median, %.2f ms p99 (CPU %.2f / %.2f ms)\nwrote %s, %s\n",
              mode_name(*mode), options.seq_dir.c_str(), records.size(), tracked, records.size() - tracked,
              unreadable, tracker->reinitialisations(), percentile(track_ms, 0.5), percentile(track_ms, 0.99),
              percentile(track_cpu_ms, 0.5), percentile(track_cpu_ms, 0.99), poses_path.c_str(), report_path.c_str());
  return 0;
}

}  // namespace
}  // namespace epichead::visp_compare

int main(int argc, char** argv) {
  using namespace epichead::visp_compare;
  CLI::App app{"Run ViSP's model-based tracker (vpMbGenericTracker) on an epichead sequence directory and write "
               "poses.csv, report.json and overlays like epichead's own tracker",
               "epichead-visp"};
  Options options;
  app.add_option("SEQ", options.seq_dir, "Sequence directory (camera.yaml, model.cao, frames, init.csv)")->required();
  app.add_option("--out", options.out_dir, "Output directory (created if missing)")->required();
  app.add_option("--mode", options.mode, "edges (moving edges only) or edges+klt (moving edges and KLT points)")
      ->capture_default_str();
  app.add_option("--overlay-every", options.overlay_every,
                 "Write overlay_NNNNNN.png every N frames, starting with the first (0: none)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and exits 0; a bad command line prints one line and exits non-zero.
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "epichead-visp: " << e.what() << " (see --help)\n";
    return 2;
  }
  return run(options);
}
