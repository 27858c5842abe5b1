// `epichead track SEQ --out DIR [--mode gradient|epic|epic+validation] [--imu off|on]`: the full
// model-based tracker over a sequence. Writes DIR/poses.csv (gt.csv columns + status; with
// --imu on the filter's estimate, and the pose estimator's own in DIR/vision_poses.csv),
// DIR/vision_covariance.csv (the pose estimator's covariance of each frame not lost, for
// `score --covariance`),
// DIR/report.json (summary + per-frame stage timings and feature counts), DIR/lines.csv (the
// candidate selected for each visible edge, for `score --lines`), overlays every Nth
// frame as DIR/overlay_NNNNNN.png and the whole run as DIR/overlay.mp4.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <expected>
#include <filesystem>
#include <vector>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "command.h"
#include "image_motion.h"
#include "percentile.h"
#include "printable.h"
#include "progress.h"
#include "selected_lines.h"
#include "track_acquisition.h"
#include "track_prediction.h"
#include "epichead/vision/model_tracker.h"
#include "epichead/vision/offline/overlay.h"
#include "epichead/vision/offline/pose_covariance_csv.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "epichead/vision/window_image.h"

namespace epichead::tools {
namespace {

using namespace epichead::vision;

struct TrackArgs {
  std::string seq, out, mode = "epic+validation", imu = "off";
  int every = 30;
  std::vector<int> zoom;  // x, y, w, h: PNG overlays show this region, enlarged

  int max_frames = 0;
  bool video = true;
  double crease_deg = 20.0;
  double max_view_deg = 85.0;
  int window_px = WindowOptions{}.width_px;
  double coast_s = 0.2;
  std::string imu_time_offset = "auto";
  std::optional<double> imu_time_offset_sigma_s;
  std::string free_turn = "auto";
  bool settle = true;
  bool outline_colours = true;
  std::string image_motion = "auto";  // follow the frame's own motion (tools/image_motion.h): auto = without the IMU
  std::uint32_t ransac_seed = RansacOptions{}.seed;
  AcquisitionOptions acquisition;
};

// Windows (grey), selected lines (green: kept by the pose, red: rejected), other candidates
// (yellow), junctions (cyan), and the model at the estimated pose (thin, by ObjectSide colour).
// One row per visible edge: the chosen candidate's end points (found = 0: none chosen) and
// whether the pose kept it as an inlier (selected_lines.h).
void write_selected_lines(std::ofstream& out, const ModelTracker& tracker, const FrameReport& report, int frame_number,
                          std::vector<SelectedLine>& scratch) {
  selected_lines(tracker, report, scratch);
  char row[192];
  for (const SelectedLine& l : scratch) {
    std::snprintf(row, sizeof row, "%d,%d,%d,%d,%.2f,%.2f,%.2f,%.2f,%d\n", frame_number, l.edge, l.found ? 1 : 0, l.candidates,
                  l.a_px.x(), l.a_px.y(), l.b_px.x(), l.b_px.y(), l.inlier ? 1 : 0);
    out << row;
  }
}

void draw_frame(cv::Mat& canvas, const ModelTracker& tracker, const FrameReport& report, const VisibleModel& at_estimate,
                int frame_number, const std::string& mode) {
  constexpr int shift = 4;
  auto P = [](const Eigen::Vector2d& p) { return cv::Point(cvRound(p.x() * 16), cvRound(p.y() * 16)); };
  OverlayStyle style;
  draw_visible_model(canvas, at_estimate, style);
  const bool validated = tracker.options().mode == TrackMode::EpicValidation;
  const auto& residuals = tracker.pose().residuals;
  for (const LineFeature& f : tracker.lines().features()) {
    if (!f.visible) continue;
    const WindowGeometry& g = f.result.geometry;
    const double x0 = g.x_of_col(0), x1 = g.x_of_col(g.cols - 1), s0 = g.s_of_row(0), s1 = g.s_of_row(g.rows - 1);
    const std::vector<cv::Point> quad{P(g.to_image(x0, s0)), P(g.to_image(x1, s0)), P(g.to_image(x1, s1)), P(g.to_image(x0, s1))};
    cv::polylines(canvas, quad, true, cv::Scalar(110, 110, 110), 1, cv::LINE_AA, shift);
    const int chosen = chosen_candidate(tracker, f);
    for (int c = 0; c < static_cast<int>(f.result.candidates.size()); ++c) {
      const LineCandidate& cand = f.result.candidates[static_cast<std::size_t>(c)];
      if (c == chosen) {
        const bool kept = report.status != TrackStatus::Lost && static_cast<std::size_t>(f.edge) < residuals.size() &&
                          residuals[static_cast<std::size_t>(f.edge)].inlier;
        cv::line(canvas, P(cand.a_px), P(cand.b_px), kept ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255), 2, cv::LINE_AA, shift);
      } else {
        cv::line(canvas, P(cand.a_px), P(cand.b_px), cv::Scalar(0, 220, 255), 1, cv::LINE_AA, shift);
      }
    }
  }
  for (const EllipseFeature& e : tracker.ellipses().features()) {
    if (!e.visible || !e.found) continue;
    const Ellipse& el = e.ellipse;
    cv::ellipse(canvas, cv::Point(cvRound(el.centre_px.x() * 16), cvRound(el.centre_px.y() * 16)),
                cv::Size(cvRound(el.semi_major_px * 16), cvRound(el.semi_minor_px * 16)), el.angle_rad * 180 / M_PI, 0, 360,
                e.weak ? cv::Scalar(0, 165, 255) : cv::Scalar(0, 255, 0), 2, cv::LINE_AA, shift);
  }
  if (validated)
    for (const ValidatedJunction& j : tracker.validation().junctions)
      cv::circle(canvas, P(j.px), 4 * 16, {255, 255, 0}, 1, cv::LINE_AA, shift);
  char caption[256];
  std::snprintf(caption, sizeof caption, "frame %d  %s  %s%s%s  lines %d/%d kept %d  %.2f ms", frame_number, mode.c_str(),
                to_string(report.status), report.reasons == TrackReason::None ? "" : " ",
                to_string(report.reasons).c_str(), report.found, report.visible, report.inliers, report.times.total_ms);
  cv::putText(canvas, caption, {8, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 3, cv::LINE_AA);
  cv::putText(canvas, caption, {8, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {255, 255, 255}, 1, cv::LINE_AA);
}

// report.json's entry for one frame: status, stage times and feature counts.
nlohmann::json frame_json(const FrameEntry& entry, const FrameReport& report) {
  const auto support = [](const std::optional<double>& s) { return s ? nlohmann::json(*s) : nlohmann::json(nullptr); };
  const EllipseRefusals& refused = report.ellipses_refused;
  nlohmann::json frame = {{"frame", entry.frame},
                     {"t_s", entry.t_s},
                     {"status", to_string(report.status)},
                     {"reasons", to_string(report.reasons)},
                     {"ms", {{"visibility", report.times.visibility_ms},
                             {"epic", report.times.epic_ms},
                             {"validation", report.times.validation_ms},
                             {"pose", report.times.pose_ms},
                             {"total", report.times.total_ms}}},
                     {"lines", {{"visible", report.visible},
                                {"found", report.found},
                                {"kept", report.inliers},
                                {"rejected", report.rejected},
                                {"recovered", report.recovered},
                                {"changed_by_validation", report.validated_changed}}},
                     {"ellipses", {{"visible", report.ellipses_visible},
                                   {"found", report.ellipses_found},
                                   {"weak", report.ellipses_weak},
                                   {"refused", {{to_string(EllipseRefusal::NoCandidate), refused.no_candidate},
                                                {to_string(EllipseRefusal::LeavesWindow), refused.leaves_window},
                                                {to_string(EllipseRefusal::OtherShape), refused.other_shape},
                                                {to_string(EllipseRefusal::FewLines), refused.few_lines}}}}},
                     {"junctions", report.junctions},
                     {"combinations", report.combinations},
                     {"scale_px", report.scale_px},
                     {"pose_iterations", report.pose_iterations}};
  // Only on a start (the first frame, the first after a loss or a detection).
  if (report.start.settled)
    frame["start"] = {{"kept", report.start.kept_gradient ? "gradient_pass" : "given"},
                      {"support_given", support(report.start.support_given)},
                      {"support_gradient_pass", support(report.start.support_gradient)}};
  return frame;
}

// The PNG overlays (every Nth frame, optionally a zoomed region) and the overlay video of a run.
class OverlayOutput {
 public:
  OverlayOutput(const TrackArgs& args, const Sequence& seq)
      : args_(args), seq_(seq), video_path_((std::filesystem::path(args.out) / "overlay.mp4").string()) {}

  // Draws the frame's overlay; writes it as a PNG when `png`, and to the video when asked for.
  std::expected<void, std::string> write(const cv::Mat& frame, const ModelTracker& tracker, const FrameReport& report,
                                         const VisibleModel& at_estimate, int frame_number, bool png) {
    cv::Mat canvas;
    if (frame.channels() == 1) cv::cvtColor(frame, canvas, cv::COLOR_GRAY2BGR);
    else if (frame.channels() == 4) cv::cvtColor(frame, canvas, cv::COLOR_BGRA2BGR);
    else canvas = frame.clone();
    draw_frame(canvas, tracker, report, at_estimate, frame_number, args_.mode);
    if (png)
      if (auto ok = write_png(canvas, frame_number); !ok) return ok;
    if (args_.video) write_video(canvas);
    return {};
  }
  void close() { video_.release(); }
  int pngs() const { return pngs_; }
  const std::string& video_path() const { return video_path_; }
  const std::string& video_note() const { return video_note_; }  // why there is no video, if there is none

 private:
  std::expected<void, std::string> write_png(const cv::Mat& canvas, int frame_number) {
    char name[64];
    std::snprintf(name, sizeof name, "overlay_%06d.png", frame_number);
    const std::string path = (std::filesystem::path(args_.out) / name).string();
    cv::Mat png_image = canvas;
    if (!args_.zoom.empty()) {
      // A close-up (the paper's Figs. 18/19 show the stiffeners this way): the region twice
      // as large, pixels kept sharp, captioned with the frame and mode.
      const cv::Rect region = cv::Rect(args_.zoom[0], args_.zoom[1], args_.zoom[2], args_.zoom[3]) & cv::Rect(0, 0, canvas.cols, canvas.rows);
      if (region.area() == 0)
        return std::unexpected("--zoom lies outside the " + std::to_string(canvas.cols) + "x" + std::to_string(canvas.rows) + " image");
      cv::resize(canvas(region), png_image, {}, 2, 2, cv::INTER_NEAREST);
      const std::string caption = "frame " + std::to_string(frame_number) + "  " + args_.mode;
      cv::putText(png_image, caption, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 3, cv::LINE_AA);
      cv::putText(png_image, caption, {8, 20}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {255, 255, 255}, 1, cv::LINE_AA);
    }
    try {
      if (!cv::imwrite(path, png_image)) return std::unexpected("cannot write " + path);
    } catch (const cv::Exception& e) {
      return std::unexpected("cannot write " + path + ": " + e.what());
    }
    ++pngs_;
    return {};
  }

  void write_video(const cv::Mat& canvas) {
    if (!video_.isOpened() && video_note_.empty()) {
      const auto& fr = seq_.frames();
      const double span_s = fr.size() > 1 ? fr.back().t_s - fr.front().t_s : 0.0;
      const double fps = span_s > 0 ? static_cast<double>(fr.size() - 1) / span_s : 30.0;
      video_.open(video_path_, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), fps, canvas.size());
      if (!video_.isOpened()) video_note_ = "OpenCV could not open an MP4 writer for " + video_path_;
    }
    if (video_.isOpened()) video_.write(canvas);
  }

  const TrackArgs& args_;
  const Sequence& seq_;
  std::string video_path_, video_note_;
  cv::VideoWriter video_;
  int pngs_ = 0;
};

// --imu-time-offset-s: "auto" (nullopt: estimated) or seconds within +-10.
std::expected<std::optional<double>, std::string> imu_time_offset(const std::string& text) {
  if (text == "auto") return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || std::abs(v) > 10)
    return std::unexpected("--imu-time-offset-s must be 'auto' or seconds within +-10, got '" + text + "'");
  return v;
}

ModelTrackerOptions tracker_options(const TrackArgs& args, TrackMode mode) {
  ModelTrackerOptions options;
  options.mode = mode;
  options.visibility.crease_angle_rad = args.crease_deg * M_PI / 180.0;
  options.visibility.max_view_angle_rad = args.max_view_deg * M_PI / 180.0;
  options.lines.epic.ransac.seed = args.ransac_seed;
  options.lines.window.width_px = args.window_px;
  options.free_turn_of_revolution = args.free_turn == "auto";
  options.settle = args.settle;
  options.outline_colours = args.outline_colours;
  return options;
}

// IMU samples the predictor could not use are counted in report.json; say so where it is seen.
void warn_dropped_imu(const nlohmann::json& predictor) {
  if (!predictor.is_object()) return;  // null: the object was never found, so nothing was predicted
  const std::uint64_t rejected = predictor.value("imu_rejected", std::uint64_t{0});
  if (rejected == 0) return;
  std::fprintf(stderr, "track: %llu IMU samples dropped (%llu saturated or beyond any sensor's range); report.json: predictor\n",
               static_cast<unsigned long long>(rejected),
               static_cast<unsigned long long>(predictor.value("imu_saturated", std::uint64_t{0})));
}

// With --imu-time-offset-s auto, what became of the camera-IMU offset. Left unestimated, the
// filter ran the whole sequence on 0 with 10 ms of doubt, and a known offset is worth much: on
// 60 held-out runs with the IMU, telling the true one raised the summed success by 92 points
// (docs/fusion.md). Bodies of revolution and scenes that barely turn never let it be estimated.
void say_time_offset(const nlohmann::json& predictor) {
  if (!predictor.is_object() || !predictor.contains("imu_time_offset_estimate")) return;  // no IMU
  const nlohmann::json& e = predictor["imu_time_offset_estimate"];
  if (!e.is_object()) return;  // told with --imu-time-offset-s
  if (e.value("adopted", false)) {
    std::printf("camera-IMU time offset estimated: %.1f ms, at %.1f s (the fit explains %.0f %% of the camera's turn)\n",
                1e3 * e.value("offset_s", 0.0), e.value("adopted_at_s", 0.0), 100 * e.value("explained", 0.0));
    return;
  }
  std::string why = e.value("shortfall", std::string("too few tracked frames"));
  if (why.empty()) why = "the fit met its bars only after the last try";  // tries are a few frames apart
  std::fprintf(stderr,
               "track: the camera-IMU time offset could not be estimated (%s): the IMU was used as if on the camera's "
               "clock, give --imu-time-offset-s if the offset is known\n",
               why.c_str());
}

// Detection for the start in one frame: the predictor made from the found pose (the sequence's
// init set to it), or nothing when the object was not found.
std::expected<std::unique_ptr<TrackPredictor>, std::string> start_from_detection(Sequence& seq, TrackAcquisition& acquisition,
                                                                                 const cv::Mat& frame, const FrameEntry& entry,
                                                                                 bool imu, const ImuClock& clock,
                                                                                 const std::optional<Eigen::Vector3d>& up_obj) {
  const auto found = acquisition.find_start(frame, entry.frame, entry.t_s);
  if (!found) return std::unexpected(found.error());
  if (!*found) return std::unique_ptr<TrackPredictor>{};
  seq.set_init({entry.frame, entry.t_s, **found, ""});
  return make_track_predictor(seq, imu, clock, up_obj);
}

struct TrackCounts {
  int tracked = 0, degraded = 0, lost = 0;
  int searched_frames = 0;  // before detection found the start
  int fused_frames = 0;     // frames whose poses.csv row is the filter's estimate
  int predicted_frames = 0; // lost frames whose poses.csv row is the filter's propagation (--coast-s)
  int fallback_frames = 0;  // frames measured from the vision-only extrapolation
  int against_gravity = 0;  // tracked poses taken as lost: their tilt contradicts the accelerometer
  int against_image_motion = 0;  // tracked poses that contradicted the frame's motion, measured again
  int against_carried_turn = 0;  // tracked poses taken as lost: turned away from the gyro's carried orientation
};

// The tracked pose's tilt against the accelerometer's down, for report.json (measured before the
// check may mark the frame lost). A pose that tilts the object away from that down is a wrong lock
// (a printed band, clutter), however well the image supports it: lost, so that detection runs.
std::optional<double> check_tilt(TrackPredictor& predictor, double t_s, FrameReport& report, TrackCounts& counts) {
  if (report.status == TrackStatus::Lost) return std::nullopt;
  const std::optional<double> error_rad = predictor.tilt_error_rad(t_s, report.cam_T_obj);
  if (predictor.against_gravity(t_s, error_rad)) {
    report.status = TrackStatus::Lost;
    report.reasons = report.reasons | vision::TrackReason::AgainstGravity;
    ++counts.against_gravity;
  }
  return error_rad;
}

// With the IMU, after its filter forgot its state in a long loss: a tracked pose turned away from
// the orientation the gyro carried is a re-lock from the prediction onto clutter (held-out
// late_entry 278: 25 deg off, on the wall beside the package, as it came into view): lost, so that
// detection runs, narrowed to that orientation.
void check_carried_turn(TrackPredictor& predictor, double t_s, FrameReport& report, TrackCounts& counts) {
  if (report.status == TrackStatus::Lost || !predictor.against_carried_turn(t_s, report.cam_T_obj)) return;
  report.status = TrackStatus::Lost;
  report.reasons = report.reasons | vision::TrackReason::AgainstCarriedTurn;
  ++counts.against_carried_turn;
}

// report.json's summary (per-frame entries and acquisition are added by the caller).
nlohmann::json report_json(const TrackArgs& args, std::size_t frames, const TrackCounts& c, const std::vector<double>& track_ms,
                           const TrackPredictor* predictor, const ModelTracker& tracker) {
  nlohmann::json j;
  j["sequence"] = args.seq;
  j["mode"] = args.mode;
  j["imu"] = args.imu;
  j["frames"] = frames;
  j["tracked"] = c.tracked + c.degraded;  // a pose was output and accepted (degraded included)
  j["tracked_clean"] = c.tracked;
  j["degraded"] = c.degraded;
  j["lost"] = c.lost;
  j["track_ms_median"] = percentile(track_ms, 0.5);
  j["track_ms_p99"] = percentile(track_ms, 0.99);
  j["track_ms_max"] = percentile(track_ms, 1.0);
  j["predictor"] = predictor ? predictor->diagnostics() : nlohmann::json(nullptr);
  j["searched_frames"] = c.searched_frames;
  j["fused_frames"] = c.fused_frames;
  j["predicted_frames"] = c.predicted_frames;
  j["fallback_frames"] = c.fallback_frames;
  j["against_gravity_frames"] = c.against_gravity;
  j["against_image_motion_frames"] = c.against_image_motion;
  j["against_carried_turn_frames"] = c.against_carried_turn;
  if (tracker.free_turn()) {
    const auto& a = *tracker.free_turn();
    j["free_turn_axis"] = {{"point_obj", {a.point_obj.x(), a.point_obj.y(), a.point_obj.z()}},
                           {"direction_obj", {a.direction_obj.x(), a.direction_obj.y(), a.direction_obj.z()}}};
  }
  return j;
}

int run_track(const TrackArgs& args) {
  const char* cmd = "track";
  static const std::map<std::string, TrackMode> modes{
      {"gradient", TrackMode::Gradient}, {"epic", TrackMode::Epic}, {"epic+validation", TrackMode::EpicValidation}};
  const auto mode = modes.find(args.mode);
  if (mode == modes.end()) return fail(cmd, "--mode must be gradient, epic or epic+validation, got '" + args.mode + "'");
  if (args.imu != "on" && args.imu != "off") return fail(cmd, "--imu must be on or off, got '" + args.imu + "'");
  if (args.image_motion != "auto" && args.image_motion != "on" && args.image_motion != "off")
    return fail(cmd, "--image-motion must be auto, on or off, got '" + args.image_motion + "'");
  if (args.free_turn != "auto" && args.free_turn != "off") return fail(cmd, "--free-turn must be auto or off, got '" + args.free_turn + "'");
  auto seq = Sequence::open(args.seq);
  if (!seq) return fail(cmd, seq.error());
  const auto offset = imu_time_offset(args.imu_time_offset);
  if (!offset) return fail(cmd, offset.error());
  const ImuClock clock{*offset, args.imu_time_offset_sigma_s};
  if (args.imu == "on" && !seq->has_imu()) return fail(cmd, "--imu on: " + seq->dir() + " has no imu.csv");
  const auto up = object_up(args.acquisition.detection);
  if (!up) return fail(cmd, up.error());
  // Without init.csv the predictor is made once detection has found the start.
  std::expected<std::unique_ptr<TrackPredictor>, std::string> predictor = std::unique_ptr<TrackPredictor>{};
  if (seq->has_init()) predictor = make_track_predictor(*seq, args.imu == "on", clock, *up);
  if (!predictor) return fail(cmd, predictor.error());

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(args.out, ec);
  if (ec) return fail(cmd, "cannot create " + args.out + ": " + ec.message());

  const ModelTrackerOptions options = tracker_options(args, mode->second);
  ModelTracker tracker(seq->model(), seq->camera(), options);
  AcquisitionOptions acquisition_options = args.acquisition;
  acquisition_options.use_imu_gravity = args.imu == "on";
  // The rechecks after a doubtful frame run with the IMU too (since 2026-12-06). They were for the
  // constant-velocity prediction alone, since a switch had taken a wrong pose (held-out mockup_walk
  // 105: 100 -> 5 %, the detection's outline scored 1.5x the object's own, partly out of view).
  // But with the IMU a wrong lock after a jolt or a cover is held steadily, and only a recheck
  // finds the object again: development acquisition runs from init.csv 1511 -> 1612 points summed
  // over 18, the other scenarios unchanged (docs/detection.md, "Rechecks with the IMU").
  TrackAcquisition acquisition(*seq, options, acquisition_options);
  Visibility overlay_visibility(seq->model(), seq->camera(), options.visibility);
  VisibleModel at_estimate;
  WindowImage image;
  FrameReport report;
  OverlayOutput overlays(args, *seq);
  // Without the IMU, the frame's own motion: a burst the constant-velocity prediction misses,
  // and a lock that contradicts it (tools/image_motion.h).
  ImageMotion image_motion(seq->model(), seq->camera(), ImageMotionOptions{});
  const bool use_image_motion = args.image_motion == "on" || (args.image_motion == "auto" && args.imu == "off");

  // Per frame and visible model edge, the candidate the tracker selected: what `epichead score
  // --lines` checks against the ground truth (did the tracker pick the right edge?).
  std::ofstream lines_csv((fs::path(args.out) / "lines.csv").string());
  if (!(lines_csv << "frame,edge,found,candidates,a_x,a_y,b_x,b_y,inlier\n")) return fail(cmd, "cannot write " + args.out + "/lines.csv");

  std::vector<StampedPose> poses, vision_poses;
  std::vector<vision::StampedCovariance> vision_covariances;
  std::vector<SelectedLine> selected;
  std::vector<double> track_ms;
  nlohmann::json per_frame = nlohmann::json::array();
  TrackCounts counts;
  std::size_t n = seq->frame_count();
  if (args.max_frames > 0) n = std::min(n, static_cast<std::size_t>(args.max_frames));
  Progress progress("track", "frames", static_cast<long>(n));  // on stderr when it is a terminal
  for (std::size_t i = 0; i < n; ++i) {
    progress.update(static_cast<long>(i));
    auto frame = seq->read_frame(i);
    if (!frame) return fail(cmd, frame.error());
    if (auto ok = image.assign(*frame); !ok) return fail(cmd, "frame " + std::to_string(i) + ": " + ok.error());
    const FrameEntry& entry = seq->frames()[i];
    if (!*predictor) {
      // No start yet: detect in this frame; frames before the start have no pose.
      auto started = start_from_detection(*seq, acquisition, *frame, entry, args.imu == "on", clock, *up);
      if (!started) return fail(cmd, started.error());
      if (!*started) {
        ++counts.searched_frames;
        per_frame.push_back({{"frame", entry.frame}, {"t_s", entry.t_s}, {"status", "searching"}});
        continue;
      }
      progress.clear();  // the message on a line of its own when stdout is the same terminal
      std::printf("frame %d: object detected; tracking from here\n", entry.frame);
      predictor = std::move(*started);
    }
    Eigen::Isometry3d predicted = (*predictor)->predict(entry.t_s);
    std::optional<Eigen::Isometry3d> fallback = (*predictor)->fallback(entry.t_s);
    if (use_image_motion) {
      image_motion.measure(*frame);
      if (const auto turned = image_motion.correct(predicted)) {
        fallback = predicted;
        predicted = *turned;
      }
    }
    tracker.track(image, predicted, fallback ? &*fallback : nullptr, report);
    std::optional<double> tilt_error_rad = check_tilt(**predictor, entry.t_s, report, counts);
    check_carried_turn(**predictor, entry.t_s, report, counts);
    if (use_image_motion) counts.against_image_motion += image_motion.check(tracker, image, report);
    if (auto ok = acquisition.after_tracking(*frame, image, entry.t_s, predicted, tracker, **predictor, report); !ok)
      return fail(cmd, ok.error());
    counts.fallback_frames += report.used_fallback;
    (*predictor)->observe(entry.t_s, report);
    bool switch_undone = false;
    if (auto before = acquisition.after_verdict(entry.t_s, (*predictor)->verdict())) {
      // The filter gated most poses after a recheck's switch: the frame is measured again from the
      // filter as it was before the switch, propagated to now (tools/switch_probation.h). The
      // image's motion (without the IMU) does not run here: the filter that judges is the IMU's.
      *predictor = std::move(before);
      tracker.reset();
      predicted = (*predictor)->predict(entry.t_s);
      fallback = (*predictor)->fallback(entry.t_s);
      tracker.track(image, predicted, fallback ? &*fallback : nullptr, report);
      tilt_error_rad = check_tilt(**predictor, entry.t_s, report, counts);
      check_carried_turn(**predictor, entry.t_s, report, counts);
      counts.fallback_frames += report.used_fallback;
      (*predictor)->observe(entry.t_s, report);
      switch_undone = true;
    }
    if (use_image_motion) image_motion.tracked(report.status != TrackStatus::Lost ? std::optional(report.cam_T_obj) : std::nullopt);
    track_ms.push_back(report.times.total_ms);
    counts.tracked += report.status == TrackStatus::Tracked;
    counts.degraded += report.status == TrackStatus::Degraded;
    counts.lost += report.status == TrackStatus::Lost;
    // With the IMU the output is the filter's estimate at the exposure time: a pose from a few
    // blurred lines is weighed against the gyro's propagation (box_clutter at jerk 2: 98 -> 100 %).
    // The pose estimator's own result stays in vision_poses.csv.
    Eigen::Isometry3d estimate = report.cam_T_obj;
    const char* status = to_string(report.status);
    if (report.status != TrackStatus::Lost) {
      if (const auto f = (*predictor)->fused(entry.t_s)) {
        estimate = *f;
        ++counts.fused_frames;
      }
    } else if (has(report.reasons, vision::TrackReason::AgainstGravity)) {
      // The image's pose was a wrong lock; the IMU's propagation is still an estimate, a doubtful one.
      if (const auto f = (*predictor)->fused(entry.t_s)) {
        estimate = *f;
        status = to_string(TrackStatus::Degraded);
        ++counts.fused_frames;
      }
    } else if (args.coast_s > 0) {
      // Vision lost this frame (blur, a board sliding in), but the filter applied a pose a moment
      // ago: its IMU propagation is the estimate, said so by the status. Longer, it drifts.
      if (const auto f = (*predictor)->coasted(entry.t_s, args.coast_s)) {
        estimate = *f;
        status = "predicted";
        ++counts.predicted_frames;
      }
    }
    poses.push_back({entry.frame, entry.t_s, estimate, status});
    if (args.imu == "on") vision_poses.push_back({entry.frame, entry.t_s, report.cam_T_obj, to_string(report.status)});
    if (report.status != TrackStatus::Lost) vision_covariances.push_back({entry.frame, entry.t_s, report.covariance});
    per_frame.push_back(frame_json(entry, report));
    // How much of the frame was converted for the windows (window_image.h), tracking and any
    // detection or recheck of this frame together.
    per_frame.back()["image_share"] = static_cast<double>(image.tiles_prepared()) / image.tiles();
    if (use_image_motion) per_frame.back()["image_motion"] = image_motion.frame_json();
    if (tilt_error_rad) per_frame.back()["tilt_error_deg"] = *tilt_error_rad * 180 / std::numbers::pi;
    if (auto filter = (*predictor)->frame_verdict(); !filter.is_null()) per_frame.back()["filter"] = std::move(filter);
    if (switch_undone) per_frame.back()["switch_undone"] = true;

    write_selected_lines(lines_csv, tracker, report, entry.frame, selected);

    const bool png = args.every > 0 && (i % static_cast<std::size_t>(args.every) == 0 || i + 1 == n);
    if (png || args.video) {
      overlay_visibility.compute(report.cam_T_obj, at_estimate);
      if (auto ok = overlays.write(*frame, tracker, report, at_estimate, entry.frame, png); !ok) return fail(cmd, ok.error());
    }
  }
  progress.finish(static_cast<long>(n));
  overlays.close();

  const std::string poses_path = (fs::path(args.out) / "poses.csv").string();
  if (auto ok = write_pose_csv(poses_path, poses); !ok) return fail(cmd, ok.error());
  if (args.imu == "on")
    if (auto ok = write_pose_csv((fs::path(args.out) / "vision_poses.csv").string(), vision_poses); !ok)
      return fail(cmd, ok.error());
  if (auto ok = write_pose_covariance_csv((fs::path(args.out) / "vision_covariance.csv").string(), vision_covariances); !ok)
    return fail(cmd, ok.error());
  nlohmann::json j = report_json(args, n, counts,
                                 track_ms, *predictor ? predictor->get() : nullptr, tracker);
  j["acquisition"] = acquisition.to_json();
  if (use_image_motion) j["image_motion"] = image_motion.to_json();
  if (!overlays.video_note().empty()) j["video_note"] = overlays.video_note();
  j["per_frame"] = std::move(per_frame);
  const std::string report_path = (fs::path(args.out) / "report.json").string();
  std::ofstream rep(report_path);
  rep << j.dump(1) << '\n';
  if (!rep.flush()) return fail(cmd, "cannot write " + report_path);
  const std::string predicted =
      args.imu == "on" ? " (" + std::to_string(counts.predicted_frames) + " of them predicted by the IMU)" : "";
  std::printf("%zu frames (%s, imu %s): %d tracked, %d degraded, %d lost%s; tracking %.3f ms median, %.3f ms p99, %.3f ms max\n",
              n, args.mode.c_str(), args.imu.c_str(), counts.tracked, counts.degraded, counts.lost, predicted.c_str(),
              percentile(track_ms, 0.5), percentile(track_ms, 0.99), percentile(track_ms, 1.0));
  std::printf("wrote %s, %s, %d overlays%s\n", poses_path.c_str(), report_path.c_str(), overlays.pngs(),
              args.video && overlays.video_note().empty() ? (" and " + overlays.video_path()).c_str() : "");
  if (!overlays.video_note().empty()) std::fprintf(stderr, "track: %s\n", printable(overlays.video_note()).c_str());
  warn_dropped_imu(j["predictor"]);
  say_time_offset(j["predictor"]);
  return 0;
}

const CommandRegistration registration{
    "track", "Track the model over a sequence (EPIC, validation, robust pose) and write poses, report and overlays",
    [](CLI::App& app) {
      auto a = std::make_shared<TrackArgs>();
      app.add_option("SEQ", a->seq,
                     "Sequence directory (camera.yaml, model.cao, frames[, init.csv, imu.csv]); without init.csv the "
                     "object is detected first")
          ->required();
      app.add_option("--out", a->out, "Output directory: poses.csv, report.json, overlay_NNNNNN.png, overlay.mp4")->required();
      app.add_option("--mode", a->mode, "gradient | epic | epic+validation (default)");
      app.add_option("--imu", a->imu, "on: predict each frame's pose with the IMU (imu.csv); off: constant velocity (default)");
      app.add_option("--every", a->every, "Write a PNG overlay every N frames and at the last (0: none; default 30)")
          ->check(CLI::Range(0, 1000000));
      app.add_option("--frames", a->max_frames, "Track only the first N frames (0: all)")->check(CLI::Range(0, 100000000));
      app.add_option("--imu-time-offset-s", a->imu_time_offset,
                     "How far the IMU clock runs ahead of the camera clock (t_camera = t_imu - offset), s, or 'auto' "
                     "(default: estimated from the gyro and the tracked poses once the camera has turned enough)");
      app.add_option("--imu-time-offset-sigma-s", a->imu_time_offset_sigma_s,
                     "How far the offset may be off (1-sigma), s: each pose is trusted the less the faster the camera "
                     "moves (default: 0 for a given offset; with auto, 0.01 until it is estimated)")
          ->check(CLI::Range(0.0, 0.1));
      app.add_flag("!--no-video", a->video, "Do not write overlay.mp4");
      app.add_option("--zoom", a->zoom, "PNG overlays show only this region (X,Y,W,H pixels), enlarged twice")
          ->delimiter(',')
          ->expected(4)
          ->check(CLI::NonNegativeNumber);
      app.add_option("--coast-s", a->coast_s,
                     "With --imu on: a frame vision loses within this long of the filter's last vision pose gets the "
                     "filter's IMU propagation, status 'predicted' (default 0.2; 0: such frames are 'lost')")
          ->check(CLI::Range(0.0, 10.0));
      app.add_option("--image-motion", a->image_motion,
                     "on: the motion of the object's region since the previous frame (phase correlation) turns a prediction "
                     "that misses a burst of camera motion, and a tracked pose that contradicts that motion is measured again; "
                     "off: the prediction alone; auto (default): on without the IMU (docs/detection.md)");
      app.add_option("--window-px", a->window_px,
                     "Samples across each model line's search window, px (default " + std::to_string(WindowOptions{}.width_px) +
                         "): how far an edge may be from its predicted place; wider follows faster motion but takes in more clutter and "
                         "costs more (docs/detection.md)")
          ->check(CLI::Range(8, kMaxWindowWidth));
      app.add_option("--crease-deg", a->crease_deg, "Crease angle of the visibility test (default 20)")->check(CLI::Range(0.0, 180.0));
      app.add_option("--max-view-deg", a->max_view_deg,
                     "Faces seen more edge-on than this (angle of normal to line of sight) count as turned away (default 85; 90: all front faces)")
          ->check(CLI::Range(0.0, 90.0));
      app.add_option("--free-turn", a->free_turn,
                     "auto (default): a model that is a body of revolution (facets and coaxial rims) leaves its turn "
                     "about the axis to the prediction, and its covariance says so; off: the pose fits all six degrees");
      app.add_flag("!--no-settle", a->settle,
                   "Measure the first frame (and the first after a loss) from the start pose only, without the "
                   "gradient pass that settles the start before the cue references are learnt");
      app.add_flag("!--no-outline-colours", a->outline_colours,
                   "On the first frame, do not weigh outline edges by the object's and the background's colours "
                   "(learnt from the model drawn at the start pose; they tell a rim from a printed border inside it)");
      app.add_option("--ransac-seed", a->ransac_seed,
                     "Seed of the line RANSAC's sampler (default 2654435769): run a few to see how much a result hangs on the draw");
      app.add_flag("!--no-reacquire", a->acquisition.reacquire,
                   "After a loss retry from the last pose only; by default detection looks for the object again once "
                   "it has been lost for --reacquire-after frames");
      app.add_option("--reacquire-after", a->acquisition.lost_frames_before_detection,
                     "Lost frames in a row before detection runs (default 3)")
          ->check(CLI::Range(1, 100000));
      add_detection_options(app, a->acquisition.detection);
      return [a]() { return run_track(*a); };
    }};

}  // namespace
}  // namespace epichead::tools
