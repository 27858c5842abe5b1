// `epichead sim-run SCENARIO --out DIR [--seconds S] [--mode fixate|stabilise|hold] ...`: the
// onboard loop, closed loop against the simulator's camera, IMU, bus and head (hardware in the
// loop, simulated time), then the same body motion with the head held fixed for comparison.
// Prints a summary and writes DIR/summary.json, DIR/bus.log (candump, stamped on the Unix epoch
// like candump's with simulated time 0 at --log-epoch; `epichead replay` reads it),
// DIR/diagnostics.jsonl, DIR/timeline.csv (the truth every millisecond: what the head
// really did, for tuning and for finding where a residual camera rate comes from),
// DIR/overlay_NNNNNN.png and DIR/*.png plots. With --soak: only the closed run, for a long
// time, with memory and the predictor's attitude error watched (no bus log, timeline or plots,
// whose growth would hide the loop's).
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <expected>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "command.h"
#include "detection_setup.h"
#include "onboard_summary_json.h"
#include "process_memory.h"
#include "progress.h"
#include "plot/line_plot.h"
#include "epichead/head/onboard_loop.h"
#include "epichead/head/target_observation.h"
#include "epichead/sim/rig.h"
#include "epichead/sim/scenario.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/sim_world.h"
#include "epichead/vision/model_centre.h"
#include "epichead/vision/model_symmetry.h"
#include "epichead/vision/offline/overlay.h"
#include "epichead/vision/offline/score.h"
#include "epichead/vision/revolution_axis.h"
#include "epichead/vision/visibility.h"

namespace epichead::tools {
namespace {

namespace fs = std::filesystem;

struct SimRunArgs {
  std::string scenario, out, mode = "fixate";
  double seconds = 0;
  int every = 30;
  int downscale = 1;
  double processing_ms = 5.0;
  long long seed = -1;
  double jerk = -1;
  double settle_s = 2.0;
  double told_backlash_rad = -1;  // < 0: the controller is told the scenario's true backlash
  bool soak = false;              // the closed run alone, watched for memory growth and attitude drift
  double soak_warmup_s = 60;
  std::string threads = "simulated";  // simulated (deterministic) | wall (vision on its own thread, as on the robot)
  bool no_init = false;    // no start pose: detection finds the object
  // Detection after a loss, as `run` does by default: on with the full-size camera in a mode that
  // tracks (fixate, hold), unless --no-reacquire; --reacquire asks for it (and fails when downscaled).
  bool reacquire = false, no_reacquire = false;
  DetectionArgs detection;
  std::optional<Eigen::Vector3d> object_up_obj;  // detection.object_up, read
  // Where simulated time 0 lands in bus.log (Unix seconds, or "now"): a fixed date by default, so
  // that the same seed writes the same log; "now" lines a run up with today's logs.
  std::string log_epoch = std::to_string(head::kSimulatedLogEpochUnix_us / 1'000'000);
  std::int64_t log_epoch_unix_us = head::kSimulatedLogEpochUnix_us;  // log_epoch, read
};

// --log-epoch: whole or fractional Unix seconds from 0 to 10^11 (a candump stamp has at most 12
// digits of seconds, and the run must fit after it), or "now".
std::expected<std::int64_t, std::string> parse_log_epoch(const std::string& text) {
  if (text == "now")
    return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  char* end = nullptr;
  const double s = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !(s >= 0 && s <= 1e11))
    return std::unexpected("--log-epoch must be Unix seconds from 0 to 1e11 or 'now', got '" + text + "'");
  return std::llround(s * 1e6);
}

// One frame's pose errors against the truth at its exposure. The tracker's own (NaN when lost)
// beside the prediction's tells a prediction that ran off from a tracker that settled on a
// wrong pose (the predictor then follows it).
struct FrameError {
  double t_s = 0;
  double predicted_attitude_deg = 0, tracked_attitude_deg = 0;
  double predicted_position_mm = 0, tracked_position_mm = 0;
};

// What one closed run measured against the simulator's truth.
struct RunMeasures {
  double cam_rate_rms_degps = 0;       // camera angular rate on the image-shifting axes (x, y)
  double cam_rate_rms_all_degps = 0;   // all three axes
  double centring_rms_px = 0, centring_max_px = 0;  // target point from the image centre
  int frames = 0, succeeded = 0;       // tracked frames within 5 cm / 5 deg of the truth
  // Frames in which a cover board hides the whole object: nothing can measure it there, so they
  // are not in `frames` (as `score` leaves sim_truth.json's object_hidden_frames out).
  int hidden = 0;
  plot::Series rate_xy{"camera rate |x,y| (deg/s)", {}, {}};
  plot::Series pan{"pan (deg)", {}, {}}, tilt{"tilt (deg)", {}, {}};
  plot::Series centring{"target from centre (px)", {}, {}};
  // --soak: resident memory (KiB) once warmed up, at the end and at most (sampled every 10 s of
  // simulated time inside the run; the end is the last such sample), and the pose errors at
  // each frame's exposure.
  double rss_warm_kib = 0, rss_end_kib = 0, rss_max_kib = 0;
  std::vector<FrameError> errors;  // sized (and touched) before the run
  std::size_t errors_filled = 0;
};

// One frame's overlay PNG: the model at the tracker's pose, captioned. Returns whether it was written.
bool write_overlay(const head::TrackedFrame& f, const vision::CadModel& model, const vision::Camera& cam,
                   const std::string& out) {
  const hw::CameraFrame& img = *f.image;
  cv::Mat bgr(img.height, img.width, CV_8UC3, const_cast<std::uint8_t*>(img.data), static_cast<std::size_t>(img.stride_bytes));
  cv::Mat canvas = bgr.clone();
  const vision::VisibleModel vis = vision::compute_visibility(model, cam, f.report->cam_T_obj);
  vision::draw_visible_model(canvas, vis);
  char caption[128];
  std::snprintf(caption, sizeof caption, "t %.3f s  %s  lines %d/%d", f.exposure_t_s, vision::to_string(f.status),
                f.report->inliers, f.report->visible);
  cv::putText(canvas, caption, {8, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 3, cv::LINE_AA);  // legible on light scenes
  cv::putText(canvas, caption, {8, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {255, 255, 255}, 1, cv::LINE_AA);
  char name[64];
  std::snprintf(name, sizeof name, "overlay_%06llu.png", static_cast<unsigned long long>(f.index));
  return cv::imwrite((fs::path(out) / name).string(), canvas);
}

// The simulator's truth, sampled every millisecond as simulated time advances: the camera's
// angular rate (for the RMS against the fixed head), the target's offset from the image centre,
// the timeline CSV and the plots' series, and with --soak the process's resident memory.
class TruthMeter {
 public:
  TruthMeter(sim::SimWorld& world, const vision::CadModel& model, const SimRunArgs& a, RunMeasures& m)
      : w_(world), a_(a), m_(m), cam_(world.camera_model()), centre_obj_(vision::model_centre(model)) {}
  std::expected<void, std::string> open_timeline(const std::string& path) {
    timeline_.open(path);
    if (!timeline_) return std::unexpected("cannot write " + path);
    timeline_ << "t_s,cam_rate_x_degps,cam_rate_y_degps,cam_rate_z_degps,pan_deg,tilt_deg,pan_rate_degps,tilt_rate_degps,"
                 "target_dx_px,target_dy_px\n";
    return {};
  }
  std::expected<void, std::string> sample(double t_s) {
    auto truth = w_.truth_at(w_.now_s());
    if (!truth) return std::unexpected(truth.error());
    const Eigen::Vector3d r = truth->cam_rate_radps * 180.0 / M_PI;
    // The RMS leaves out the first settle_s: the head's first slew toward the target is wanted
    // motion, not disturbance (the same window is left out of the fixed-head run).
    if (truth->t_s >= a_.settle_s) {
      sq_xy_ += r.x() * r.x() + r.y() * r.y();
      sq_all_ += r.squaredNorm();
      ++samples_;
    }
    const Eigen::Vector2d off = head::offset_from_centre_px(cam_, truth->cam_T_obj * centre_obj_);
    if (off.allFinite()) {
      sq_centre_ += off.squaredNorm();
      ++centre_n_;
      m_.centring_max_px = std::max(m_.centring_max_px, off.norm());
    }
    if (timeline_.is_open()) write_row(*truth, r, off);
    if (a_.soak) sample_memory(t_s);
    else if (samples_ % 10 == 0) sample_plots(t_s, *truth, r, off);  // plots at 100 Hz
    return {};
  }
  void finish() {
    m_.cam_rate_rms_degps = samples_ ? std::sqrt(sq_xy_ / static_cast<double>(samples_)) : 0;
    m_.cam_rate_rms_all_degps = samples_ ? std::sqrt(sq_all_ / static_cast<double>(samples_)) : 0;
    m_.centring_rms_px = centre_n_ ? std::sqrt(sq_centre_ / static_cast<double>(centre_n_)) : 0;
  }

 private:
  void write_row(const sim::SimTruth& truth, const Eigen::Vector3d& r, const Eigen::Vector2d& off) {
    constexpr double deg = 180.0 / M_PI;
    char row[256];
    std::snprintf(row, sizeof row, "%.4f,%.4f,%.4f,%.4f,%.5f,%.5f,%.4f,%.4f,%.2f,%.2f\n", truth.t_s, r.x(), r.y(), r.z(),
                  truth.joints.pan_rad * deg, truth.joints.tilt_rad * deg, truth.joints.pan_rate_radps * deg,
                  truth.joints.tilt_rate_radps * deg, off.x(), off.y());
    timeline_ << row;
  }
  void sample_memory(double t_s) {
    const long ms = std::lround(t_s * 1e3);
    if (ms % 10000 != 0 && !(m_.rss_warm_kib == 0 && t_s >= a_.soak_warmup_s)) return;
    const double rss = resident_kib().value_or(0);
    m_.rss_max_kib = std::max(m_.rss_max_kib, rss);
    m_.rss_end_kib = rss;  // the last sample inside the run: the summary's own copies come after
    if (m_.rss_warm_kib == 0 && t_s >= a_.soak_warmup_s) m_.rss_warm_kib = rss;
  }
  void sample_plots(double t_s, const sim::SimTruth& truth, const Eigen::Vector3d& r, const Eigen::Vector2d& off) {
    m_.rate_xy.x.push_back(t_s);
    m_.rate_xy.y.push_back(std::hypot(r.x(), r.y()));
    m_.pan.x.push_back(t_s);
    m_.pan.y.push_back(truth.joints.pan_rad * 180 / M_PI);
    m_.tilt.x.push_back(t_s);
    m_.tilt.y.push_back(truth.joints.tilt_rad * 180 / M_PI);
    m_.centring.x.push_back(t_s);
    m_.centring.y.push_back(off.allFinite() ? off.norm() : std::nan(""));
  }
  sim::SimWorld& w_;
  const SimRunArgs& a_;
  RunMeasures& m_;
  vision::Camera cam_;
  Eigen::Vector3d centre_obj_;
  std::ofstream timeline_;
  double sq_xy_ = 0, sq_all_ = 0, sq_centre_ = 0;
  long samples_ = 0, centre_n_ = 0;
};

// Each published frame against the truth: success (5 cm / 5 deg), the soak's attitude error,
// and the overlays.
// `symmetries`: the model's own (model_symmetry.h), since a detected start may be any of them;
// `free_axis_obj`: a body of revolution's axis, whose turn is removed first (as `score
// --sym-axis`), since its edges cannot show it.
void measure_frame(const head::TrackedFrame& f, sim::SimWorld& w, const SimRunArgs& a,
                   const std::vector<Eigen::Isometry3d>& symmetries, const std::optional<Eigen::Vector3d>& free_axis_obj,
                   RunMeasures& m) {
  const auto truth = w.truth_at(f.exposure_t_s);
  if (a.soak) {
    if (truth && m.errors_filled < m.errors.size()) {
      const auto angle_deg = [&](const Eigen::Isometry3d& p) {
        return Eigen::AngleAxisd(p.linear() * truth->cam_T_obj.linear().transpose()).angle() * 180 / M_PI;
      };
      const auto distance_mm = [&](const Eigen::Isometry3d& p) {
        return (p.translation() - truth->cam_T_obj.translation()).norm() * 1e3;
      };
      const bool lost = f.status == vision::TrackStatus::Lost;
      m.errors[m.errors_filled++] = {f.exposure_t_s, angle_deg(f.predicted_cam_T_obj),
                                     lost ? std::nan("") : angle_deg(f.report->cam_T_obj),
                                     distance_mm(f.predicted_cam_T_obj),
                                     lost ? std::nan("") : distance_mm(f.report->cam_T_obj)};
    }
  }
  if (truth && w.object_hidden(*truth)) {
    ++m.hidden;
    return;
  }
  if (f.status != vision::TrackStatus::Lost) {
    if (truth) {
      bool success = false;
      for (std::size_t k = 0; k <= symmetries.size() && !success; ++k) {
        Eigen::Isometry3d est = k == 0 ? f.report->cam_T_obj : f.report->cam_T_obj * symmetries[k - 1];
        if (free_axis_obj) est.linear() = vision::remove_turn(truth->cam_T_obj.linear(), est.linear(), *free_axis_obj);
        const double rot_deg = Eigen::AngleAxisd(est.linear() * truth->cam_T_obj.linear().transpose()).angle() * 180 / M_PI;
        const double t_m = (est.translation() - truth->cam_T_obj.translation()).norm();
        success = rot_deg <= 5.0 && t_m <= 0.05;
      }
      m.succeeded += success;
    }
  }
  ++m.frames;
}

// Why detection does not run, or nullptr when it does: always without a start pose; after a loss
// when asked, or by default (as `run`) with the full-size camera the templates are made for, in a
// mode that tracks.
const char* why_no_reacquisition(const SimRunArgs& a, head::ControlMode mode) {
  if (a.no_init || a.reacquire) return nullptr;
  if (a.no_reacquire) return "--no-reacquire";
  if (a.downscale != 1) return "detection needs --downscale 1";
  if (mode == head::ControlMode::Stabilise) return "mode stabilise";
  return nullptr;
}

// Where one run's frames go on the progress line: the runs one after the other.
struct RunProgress {
  Progress& line;
  long first_frame;  // frames of the runs before this one
  double fps;
};

// One closed run. `detector` (may be null) finds the object without a start pose (--no-init)
// and after losses; the run takes it.
std::expected<head::OnboardSummary, std::string> run_once(const sim::Scenario& scenario, const SimRunArgs& a,
                                                          head::ControlMode mode, bool render, const std::string& out,
                                                          RunMeasures& m, const RunProgress& progress,
                                                          std::unique_ptr<vision::Detector> detector = {}) {
  sim::SimWorldOptions wo;
  wo.camera = render ? sim::CameraOutput::Render : sim::CameraOutput::Blank;
  wo.camera_downscale = a.downscale;
  auto world = sim::SimWorld::create(scenario, wo);
  if (!world) return std::unexpected(world.error());
  sim::SimWorld& w = **world;
  auto model = sim::make_scene_model(scenario.scene);
  if (!model) return std::unexpected(model.error());

  head::OnboardOptions o;
  o.mode = mode;
  // The head's gear backlash as the controller's calibration: the simulator knows the truth
  // (scenario key head_backlash_rad, both joints); on the robot it comes from the configuration.
  // --told-backlash-rad gives it another figure (0: not told), as a mis-calibrated robot would.
  const double told = a.told_backlash_rad >= 0 ? a.told_backlash_rad : scenario.head_dynamics.backlash_rad;
  o.controller.backlash = {told, told};
  o.processing_s = a.processing_ms * 1e-3;
  // --object-up: the predictor checks the object's tilt against it from the start, and detection
  // takes it as its gravity prior (through the predictor's down).
  if (a.object_up_obj) o.predictor.gravity_check.told_down_obj = -*a.object_up_obj;
  const bool wall = a.threads == "wall";
  if (wall) o.threads = head::VisionThreads::Thread;  // processing_s is then what tracking really takes
  o.simulated_log_epoch_unix_us = a.log_epoch_unix_us;
  if (render) {
    if (!a.soak) o.candump_path = (fs::path(out) / "bus.log").string();
    o.diagnostics_path = (fs::path(out) / "diagnostics.jsonl").string();
  }
  const vision::Camera cam = w.camera_model();
  const std::vector<Eigen::Isometry3d> symmetries = vision::model_symmetries(*model);
  std::optional<Eigen::Vector3d> free_axis_obj;
  if (const auto axis = vision::find_revolution_axis(*model)) free_axis_obj = axis->direction_obj.normalized();
  TruthMeter meter(w, *model, a, m);
  if (render && !a.soak)
    if (auto ok = meter.open_timeline((fs::path(out) / "timeline.csv").string()); !ok) return std::unexpected(ok.error());
  head::OnboardPorts ports;
  ports.clock = &w.clock();
  ports.bus = &w.bus();
  ports.camera = &w.camera();
  ports.simulated = true;
  // With wall-clock threads the simulated time keeps pace with the wall clock (never ahead of it),
  // so that the vision thread works against the control loop's real rate, as on the robot.
  const auto wall_start = std::chrono::steady_clock::now();
  const double sim_start_s = w.now_s();
  ports.wait_until = [&](double t_s) -> std::expected<void, std::string> {
    if (auto ok = w.advance_to(t_s); !ok) return ok;
    if (wall) std::this_thread::sleep_until(wall_start + std::chrono::duration<double>(t_s - sim_start_s));
    progress.line.update(progress.first_frame + static_cast<long>(t_s * progress.fps));  // cheap: throttled, no allocation
    return meter.sample(t_s);
  };
  auto loop = head::OnboardLoop::create(*model, cam, o, ports);
  if (!loop) return std::unexpected((*&loop).error());
  if (detector) (*loop)->set_detector(std::move(detector));
  if (!a.no_init) {
    // The tracker starts like `epichead track` from init.csv: the truth perturbed by 1 cm and 1 deg.
    auto truth0 = w.truth_at(w.now_s());
    if (!truth0) return std::unexpected(truth0.error());
    Eigen::Isometry3d init = truth0->cam_T_obj;
    init.linear() = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d(1, 1, 1).normalized()).toRotationMatrix() * init.linear();
    init.translation() += Eigen::Vector3d(0.006, -0.006, 0.005);
    (*loop)->set_initial_pose(w.now_s(), init);
  }

  int overlays = 0;
  const double until = a.seconds > 0 ? a.seconds : scenario.first_frame_s + scenario.frames / scenario.fps;
  // Sized up front (so its pages are resident before the baseline): the measuring must not grow.
  if (a.soak) m.errors.assign(static_cast<std::size_t>(until * scenario.fps) + 16, FrameError{});
  const head::FrameHook hook = [&](const head::TrackedFrame& f) {
    measure_frame(f, w, a, symmetries, free_axis_obj, m);
    if (!render || a.every <= 0 || f.index % static_cast<std::uint64_t>(a.every) != 0) return;
    overlays += write_overlay(f, *model, cam, out);
  };
  auto summary = (*loop)->run(std::min(until, w.horizon_s()), hook);
  if (!summary) return summary;
  m.errors.resize(m.errors_filled);
  meter.finish();
  return summary;
}

// Median of the predicted attitude errors with t_s in [t0, t1), or -1 when there are none.
double median_error_deg(const std::vector<FrameError>& errors, double t0, double t1) {
  std::vector<double> v;
  for (const FrameError& e : errors)
    if (e.t_s >= t0 && e.t_s < t1) v.push_back(e.predicted_attitude_deg);
  if (v.empty()) return -1;
  std::nth_element(v.begin(), v.begin() + static_cast<long>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// --soak: memory after warm-up and at the end, the predictor's attitude error early and late,
// the loop's summary (faults and recoveries are in diagnostics.jsonl's events).
int report_soak(const sim::Scenario& scenario, const SimRunArgs& a, const head::OnboardSummary& run, const RunMeasures& m) {
  const double end_s = m.errors.empty() ? 0 : m.errors.back().t_s;
  const double window_s = std::max(1.0, 0.1 * (end_s - a.soak_warmup_s));
  const double early = median_error_deg(m.errors, a.soak_warmup_s, a.soak_warmup_s + window_s);
  const double late = median_error_deg(m.errors, end_s - window_s, end_s + 1);
  const nlohmann::json j{{"scenario", scenario.name},
                         {"mode", a.mode},
                         {"seed", scenario.seed},
                         {"soak", {{"warmup_s", a.soak_warmup_s},
                                   {"end_s", end_s},
                                   {"rss_kib_after_warmup", m.rss_warm_kib},
                                   {"rss_kib_end", m.rss_end_kib},
                                   {"rss_kib_max", m.rss_max_kib},
                                   {"attitude_window_s", window_s},
                                   {"predicted_attitude_error_deg_median_early", early},
                                   {"predicted_attitude_error_deg_median_late", late},
                                   {"frames", m.frames}}},
                         {"loop", summary_json(run)}};
  const std::string summary_path = (fs::path(a.out) / "summary.json").string();
  std::ofstream(summary_path) << j.dump(1) << '\n';
  // The error at every frame, for finding when and how it grew.
  const std::string errors_path = (fs::path(a.out) / "attitude_error.csv").string();
  std::ofstream errors(errors_path);
  errors << "t_s,predicted_attitude_error_deg,tracked_attitude_error_deg,predicted_position_error_mm,"
            "tracked_position_error_mm\n";
  for (const FrameError& e : m.errors)
    errors << e.t_s << ',' << e.predicted_attitude_deg << ',' << e.tracked_attitude_deg << ','
           << e.predicted_position_mm << ',' << e.tracked_position_mm << '\n';
  std::printf("sim-run %s --soak (%s, seed %llu): %.0f s simulated, %d frames (%llu tracked, %llu lost)\n",
              scenario.name.c_str(), a.mode.c_str(), static_cast<unsigned long long>(scenario.seed), end_s, m.frames,
              static_cast<unsigned long long>(run.tracked), static_cast<unsigned long long>(run.lost));
  std::printf("  memory: %.0f KiB resident after %.0f s, %.0f KiB at the end, %.0f KiB at most\n", m.rss_warm_kib,
              a.soak_warmup_s, m.rss_end_kib, m.rss_max_kib);
  std::printf("  predicted attitude error at exposure: %.3f deg median over the first %.0f s after warm-up, %.3f deg over "
              "the last %.0f s\n",
              early, window_s, late, window_s);
  std::printf("  wrote %s, %s and %s\n", summary_path.c_str(), errors_path.c_str(),
              (fs::path(a.out) / "diagnostics.jsonl").c_str());
  return 0;
}

int run_sim_run(const SimRunArgs& given) {
  const char* cmd = "sim-run";
  SimRunArgs a = given;
  if (auto epoch = parse_log_epoch(a.log_epoch)) a.log_epoch_unix_us = *epoch;
  else return fail(cmd, epoch.error());
  if (auto up = object_up(a.detection)) a.object_up_obj = *up;
  else return fail(cmd, up.error());
  static const std::map<std::string, head::ControlMode> modes{
      {"fixate", head::ControlMode::Fixate}, {"stabilise", head::ControlMode::Stabilise}, {"hold", head::ControlMode::Hold}};
  const auto mode = modes.find(a.mode);
  if (mode == modes.end()) return fail(cmd, "--mode must be fixate, stabilise or hold, got '" + a.mode + "'");
  auto scenario = sim::find_scenario(a.scenario);
  if (!scenario) return fail(cmd, scenario.error());
  if (a.seed >= 0) {
    // The seed draws the body's motion too (each step's burst, the hand's sway), not only the
    // sensors' noise: otherwise every seed would walk the same steps.
    scenario->seed = scenario->walking.seed = scenario->handheld.seed = static_cast<std::uint64_t>(a.seed);
  }
  if (a.jerk >= 0) scenario->walking.jerk = a.jerk;
  std::error_code ec;
  fs::create_directories(a.out, ec);
  if (ec) return fail(cmd, "cannot create " + a.out + ": " + ec.message());

  // Detection (--no-init, re-acquisition) for the rendered run: the templates are built (or read)
  // before the simulated time starts.
  const char* const no_reacquisition = why_no_reacquisition(a, mode->second);
  const bool reacquiring = no_reacquisition == nullptr;
  std::unique_ptr<vision::Detector> detector;
  if (reacquiring) {
    auto model = sim::make_scene_model(scenario->scene);
    if (!model) return fail(cmd, model.error());
    auto camera = sim::scenario_camera(*scenario);
    if (!camera) return fail(cmd, camera.error());
    if (a.downscale != 1) return fail(cmd, "--no-init and --reacquire need the full-size camera (--downscale 1)");
    auto d = make_detector(cmd, *model, *camera, a.detection, head::OnboardOptions{}.tracker);
    if (!d) return fail(cmd, d.error());
    detector = std::move(*d);
  }
  // Fixation turns the camera on purpose (toward the target); the stabilisation figure comes
  // from a run in stabilise mode (blank camera: that mode does not use vision).
  const bool fixating = mode->second == head::ControlMode::Fixate;
  // Progress on stderr when it is a terminal (progress.h): the simulated frames of every run.
  const double until_s = a.seconds > 0 ? a.seconds : scenario->first_frame_s + scenario->frames / scenario->fps;
  const long run_frames = std::lround(until_s * scenario->fps);
  Progress progress("sim-run", "frames", run_frames * (a.soak ? 1 : fixating ? 3 : 2));
  RunMeasures closed, fixed, stabilised;
  auto run = run_once(*scenario, a, mode->second, true, a.out, closed, {progress, 0, scenario->fps}, std::move(detector));
  if (!run) return fail(cmd, run.error());
  if (a.soak) {
    progress.finish();
    return report_soak(*scenario, a, *run, closed);
  }
  if (fixating) {
    auto st = run_once(*scenario, a, head::ControlMode::Stabilise, false, a.out, stabilised, {progress, run_frames, scenario->fps});
    if (!st) return fail(cmd, "stabilise run: " + st.error());
  } else {
    stabilised = closed;
  }
  // The comparison: the same body motion with the head held still (no rendering needed).
  auto held = run_once(*scenario, a, head::ControlMode::Hold, false, a.out, fixed,
                       {progress, (fixating ? 2 : 1) * run_frames, scenario->fps});
  if (!held) return fail(cmd, "fixed-head run: " + held.error());
  progress.finish(progress.total());

  const double success = closed.frames ? static_cast<double>(closed.succeeded) / closed.frames : 0.0;
  const double reduction =
      stabilised.cam_rate_rms_degps > 0 ? fixed.cam_rate_rms_degps / stabilised.cam_rate_rms_degps : 0.0;
  nlohmann::json j{{"scenario", scenario->name},
                   {"mode", a.mode},
                   {"seed", scenario->seed},
                   {"processing_ms", a.processing_ms},
                   {"threads", a.threads},
                   {"reacquire", reacquiring},
                   {"tracking_success", success},
                   {"frames", closed.frames},
                   {"hidden_frames", closed.hidden},
                   {"camera_rate_rms_degps", {{"closed_loop", closed.cam_rate_rms_degps}, {"fixed_head", fixed.cam_rate_rms_degps},
                                              {"stabilise", stabilised.cam_rate_rms_degps},
                                              {"reduction", reduction}, {"reduction_of", "stabilise vs fixed_head"},
                                              {"from_t_s", a.settle_s},
                                              {"axes", "x,y (image-shifting); roll cannot be cancelled"},
                                              {"closed_loop_all_axes", closed.cam_rate_rms_all_degps},
                                              {"fixed_head_all_axes", fixed.cam_rate_rms_all_degps}}},
                   {"centring_px", {{"rms", closed.centring_rms_px}, {"max", closed.centring_max_px},
                                    {"fixed_head_rms", fixed.centring_rms_px}}},
                   {"loop", summary_json(*run)}};
  const std::string summary_path = (fs::path(a.out) / "summary.json").string();
  std::ofstream(summary_path) << j.dump(1) << '\n';

  plot::Figure fig;
  fig.title = "sim-run " + scenario->name + " (" + a.mode + ")";
  plot::Panel rate{"camera angular rate on the image axes", "t (s)", "deg/s", {}};
  closed.rate_xy.label = "closed loop";
  fixed.rate_xy.label = "head fixed";
  rate.series = {fixed.rate_xy, closed.rate_xy};
  if (fixating) {
    closed.rate_xy.label = "closed loop (fixate)";
    stabilised.rate_xy.label = "closed loop (stabilise)";
    rate.series = {fixed.rate_xy, closed.rate_xy, stabilised.rate_xy};
  }
  plot::Panel joints{"head joints", "t (s)", "deg", {closed.pan, closed.tilt}};
  plot::Panel centre{"target distance from the image centre", "t (s)", "px", {}};
  closed.centring.label = "closed loop";
  fixed.centring.label = "head fixed";
  centre.series = {fixed.centring, closed.centring};
  fig.panels = {rate, joints, centre};
  const std::string plot_path = (fs::path(a.out) / "sim_run.png").string();
  if (auto ok = plot::write_png(fig, plot_path); !ok) return fail(cmd, ok.error());

  std::printf("sim-run %s (%s, seed %llu): %d frames, tracking success %.1f %%", scenario->name.c_str(), a.mode.c_str(),
              static_cast<unsigned long long>(scenario->seed), closed.frames, 100 * success);
  if (closed.hidden > 0) std::printf(" (%d frames with the object hidden by a cover left out)", closed.hidden);
  std::printf("\n");
  if (reacquiring)
    std::printf("  re-acquisition on: %llu losses, %llu found again by detection\n",
                static_cast<unsigned long long>(run->losses), static_cast<unsigned long long>(run->reacquisitions));
  else
    std::printf("  re-acquisition off (%s): after a loss the tracker retries from its last pose only\n", no_reacquisition);
  std::printf("  camera rate RMS (x,y, after %.1f s): %.2f deg/s stabilised vs %.2f deg/s head fixed (%.1fx lower)",
              a.settle_s, stabilised.cam_rate_rms_degps, fixed.cam_rate_rms_degps, reduction);
  if (fixating) std::printf("; %.2f deg/s while fixating", closed.cam_rate_rms_degps);
  std::printf("\n");
  std::printf("  target from image centre: %.1f px RMS (max %.1f) vs %.1f px RMS head fixed\n", closed.centring_rms_px,
              closed.centring_max_px, fixed.centring_rms_px);
  std::printf("  control loop: %llu ticks (%llu late), work %.1f us median / %.1f us p99 / %.1f us max per tick on the "
              "control thread (wall; vision, rendering and the overlays excluded); %llu frames dropped while vision was busy\n",
              static_cast<unsigned long long>(run->ticks), static_cast<unsigned long long>(run->late_ticks),
              run->tick_work_us_median, run->tick_work_us_p99, run->tick_work_us_max,
              static_cast<unsigned long long>(run->frames_dropped_vision_busy));
  std::printf("  exposure -> command %.2f ms median (%.2f max) = frame age when taken %.2f ms + processing %.2f ms + "
              "result -> command <= %.2f ms\n",
              run->exposure_to_command_ms_median, run->exposure_to_command_ms_max, run->frame_age_at_take_ms_median,
              a.processing_ms, run->result_to_command_ms_max);
  std::printf("  tracking %.3f ms median per frame (wall); bus log %s (%llu frames), diagnostics %s\n", run->track_ms_median,
              (fs::path(a.out) / "bus.log").c_str(), static_cast<unsigned long long>(run->frames_logged),
              (fs::path(a.out) / "diagnostics.jsonl").c_str());
  std::printf("  wrote %s, %s and overlays in %s\n", summary_path.c_str(), plot_path.c_str(), a.out.c_str());
  return 0;
}

const CommandRegistration registration{
    "sim-run", "Closed-loop hardware-in-the-loop run of the onboard loop against the simulator", [](CLI::App& app) {
      auto a = std::make_shared<SimRunArgs>();
      app.add_option("SCENARIO", a->scenario, "Built-in scenario name or .scn file")->required();
      app.add_option("--out", a->out, "Output directory")->required();
      app.add_option("--mode", a->mode, "Head mode: fixate (default), stabilise or hold");
      app.add_option("--seconds", a->seconds, "Simulated time to run (default: the scenario's frames)")->check(CLI::Range(0.0, 1e6));
      app.add_option("--every", a->every, "Overlay every N tracked frames (0: none)")->check(CLI::Range(0, 1000000));
      app.add_option("--downscale", a->downscale, "Render a smaller camera: 1, 2, 4 or 8")->check(CLI::IsMember({1, 2, 4, 8}));
      app.add_option("--processing-ms", a->processing_ms, "Modelled vision processing time (default 5)")->check(CLI::Range(0.0, 1000.0));
      app.add_option("--seed", a->seed, "Override the scenario's seed (the sensors' noise and the body's steps)");
      app.add_option("--jerk", a->jerk, "Override the walking motion's jerk scale")->check(CLI::Range(0.0, 100.0));
      app.add_option("--threads", a->threads,
                     "simulated: vision inline, results published after --processing-ms of simulated time (deterministic, "
                     "default); wall: vision and recording on threads of their own in real time, as on the robot")
          ->check(CLI::IsMember({"simulated", "wall"}));
      app.add_option("--settle-s", a->settle_s, "Leave the first S seconds (the first slew) out of the rate RMS (default 2)")
          ->check(CLI::Range(0.0, 1e6));
      auto* no_init = app.add_flag("--no-init", a->no_init,
                                   "Give the loop no start pose: detection finds the object (and finds it again after a loss)");
      auto* on = app.add_flag("--reacquire", a->reacquire,
                              "Detection finds the object again after a loss (the default with the full-size camera "
                              "and a mode that tracks, as `run` does; an error with --downscale above 1)");
      app.add_flag("--no-reacquire", a->no_reacquire, "After a loss retry from the last pose only (no detection)")
          ->excludes(on)
          ->excludes(no_init);
      app.add_option("--log-epoch", a->log_epoch,
                     "Unix time (s) at which simulated time 0 is written in bus.log, as candump stamps on the wall "
                     "clock (default 1704067200, 2024-01-01T00:00:00Z, so a seed gives the same log; 'now': the "
                     "current time)");
      add_detection_options(app, a->detection);
      app.add_flag("--soak", a->soak,
                   "Soak run: the closed run alone (no comparison runs, bus log, timeline or plots), reporting resident "
                   "memory after --soak-warmup-s and at the end and the predictor's attitude error early and late");
      app.add_option("--soak-warmup-s", a->soak_warmup_s, "Warm-up before the soak's memory baseline (default 60)")
          ->check(CLI::Range(0.0, 1e6));
      app.add_option("--told-backlash-rad", a->told_backlash_rad,
                     "The gear backlash the controller is told (default: the scenario's true head_backlash_rad; 0: none)")
          ->check(CLI::Range(0.0, 0.5));
      return [a]() { return run_sim_run(*a); };
    }};

}  // namespace
}  // namespace epichead::tools
