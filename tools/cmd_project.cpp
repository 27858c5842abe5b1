// `epichead project SEQ --frame N --out overlay.png`: draws the visible model over a frame of a
// sequence at the ground-truth pose (gt.csv) or else the starting pose (init.csv).
#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command.h"
#include "epichead/vision/offline/overlay.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/visibility.h"

namespace epichead::tools {
namespace {

using namespace epichead::vision;

int run_project(const std::string& seq_dir, int frame, const std::string& out_path, double crease_deg) {
  auto seq = Sequence::open(seq_dir);
  if (!seq) return fail("project", seq.error());
  if (frame < 0 || static_cast<std::size_t>(frame) >= seq->frame_count())
    return fail("project", "frame " + std::to_string(frame) + " out of range (the sequence has " +
                               std::to_string(seq->frame_count()) + " frames)");
  const int frame_number = seq->frames()[frame].frame;
  Eigen::Isometry3d cam_T_obj = seq->init().cam_T_obj;
  std::string pose_source = "init.csv";
  bool found = false;
  for (const auto& p : seq->ground_truth()) {
    if (p.frame == frame_number) { cam_T_obj = p.cam_T_obj; pose_source = "gt.csv"; found = true; break; }
  }
  if (!found && !seq->has_init())
    return fail("project", "no gt.csv pose for frame " + std::to_string(frame_number) + " and no init.csv");
  if (!found && seq->init().frame != frame_number)
    std::cerr << "epichead project: note: no gt.csv pose for frame " << frame_number
              << "; drawing the init.csv pose of frame " << seq->init().frame << "\n";
  auto image = seq->read_frame(static_cast<std::size_t>(frame));
  if (!image) return fail("project", image.error());

  VisibilityOptions options;
  options.crease_angle_rad = crease_deg * M_PI / 180;
  Visibility visibility(seq->model(), seq->camera(), options);
  VisibleModel visible;
  visibility.compute(cam_T_obj, visible);
  cv::Mat canvas = image->clone();
  draw_visible_model(canvas, visible);
  const std::string caption = "frame " + std::to_string(frame_number) + "  pose: " + pose_source + "  edges " +
                              std::to_string(visible.edges.size()) + "  ellipses " + std::to_string(visible.ellipses.size());
  cv::putText(canvas, caption, {8, 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {255, 255, 255}, 1, cv::LINE_AA);
  cv::putText(canvas, "object side: left green, right magenta, both yellow (tick points to the object)",
              {8, canvas.rows - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {255, 255, 255}, 1, cv::LINE_AA);
  try {
    if (!cv::imwrite(out_path, canvas)) return fail("project", "cannot write " + out_path);
  } catch (const cv::Exception& e) {
    return fail("project", "cannot write " + out_path + ": " + e.what());
  }
  std::cout << "wrote " << out_path << " (" << visible.edges.size() << " visible edge pieces, "
            << visible.ellipses.size() << " ellipses, pose from " << pose_source << ")\n";
  return 0;
}

const CommandRegistration registration{
    "project", "Draw the visible model over a frame of a sequence (pose from gt.csv, else init.csv)",
    [](CLI::App& app) {
      auto seq = std::make_shared<std::string>();
      auto out = std::make_shared<std::string>();
      auto frame = std::make_shared<int>(0);
      auto crease_deg = std::make_shared<double>(20.0);
      app.add_option("SEQ", *seq, "Sequence directory")->required();
      app.add_option("--frame", *frame, "Frame index (0-based position in the sequence)");
      app.add_option("--out", *out, "Output PNG")->required();
      app.add_option("--crease-deg", *crease_deg, "Crease angle: edges between faces closer than this are not drawn")
          ->check(CLI::Range(0.0, 180.0));
      return [=]() { return run_project(*seq, *frame, *out, *crease_deg); };
    }};

}  // namespace
}  // namespace epichead::tools
