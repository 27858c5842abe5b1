#include "epichead/sim/sequence_writer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "epichead/sim/imu_model.h"
#include "epichead/sim/occlusion_truth.h"
#include "epichead/sim/renderer.h"
#include "epichead/sim/rig.h"
#include "epichead/sim/scene_library.h"
#include "epichead/sim/scene_variety.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "occluder_motion.h"
#include "simulate_random.h"

namespace epichead::sim {
namespace {

namespace fs = std::filesystem;
constexpr double rad2deg = 180.0 / std::numbers::pi;

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
std::string vec(const Eigen::Vector3d& v) { return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]"; }

std::expected<void, std::string> prepare_dir(const std::string& out_dir) {
  std::error_code ec;
  if (fs::exists(out_dir, ec)) {
    if (!fs::is_directory(out_dir, ec)) return std::unexpected(out_dir + " exists and is not a directory");
    const bool empty = fs::is_empty(out_dir, ec);
    if (!empty && !fs::exists(fs::path(out_dir) / "sim_truth.json"))
      return std::unexpected(out_dir + " is not empty and not an earlier simulator output; refusing to overwrite");
    // Old frames could outnumber the new ones; frames.csv would ignore them, but a copy would not.
    fs::remove_all(fs::path(out_dir) / "frames", ec);
  }
  fs::create_directories(fs::path(out_dir) / "frames", ec);
  if (ec) return std::unexpected("cannot create " + out_dir + "/frames: " + ec.message());
  return {};
}

std::expected<void, std::string> write_text(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) return std::unexpected("cannot write " + path.string());
  return {};
}

using FrameRuns = std::vector<std::pair<int, int>>;

// The runs of frames [first, last] of gt for which `keep` holds.
template <typename Keep>
FrameRuns frame_runs(const std::vector<vision::StampedPose>& gt, Keep keep) {
  FrameRuns runs;
  for (const auto& g : gt) {
    if (!keep(g)) continue;
    if (!runs.empty() && runs.back().second == g.frame - 1) runs.back().second = g.frame;
    else runs.push_back({g.frame, g.frame});
  }
  return runs;
}

// The runs of frames in which the whole model lies inside the image and no cover board is in
// front of the camera: where a tracker can see all of the object (an acquisition evaluation
// counts frames to re-acquire from the start of each run).
FrameRuns object_in_view_runs(const Scenario& s, const std::vector<vision::StampedPose>& gt, const vision::CadModel& model,
                              const vision::Camera& camera) {
  const std::vector<Eigen::Vector3d> outline = vision::outline_points(model);
  return frame_runs(gt, [&](const vision::StampedPose& g) {
    const bool covered = std::any_of(s.covers.begin(), s.covers.end(), [&](const CoverWindow& w) { return w.board_in_view(g.t_s); });
    return !covered && std::all_of(outline.begin(), outline.end(), [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3d q = g.cam_T_obj * p;
      return q.z() > 1e-6 && camera.in_image(camera.project(q));
    });
  });
}

// The runs of frames in which occluders (a cover board) hide the whole object: no tracker can
// measure it there, so scoring leaves them out. Frames with any of it in sight count.
FrameRuns object_hidden_runs(const Scene& scene, const Scenario& s, const std::vector<vision::StampedPose>& gt) {
  OcclusionTruth occlusion(scene, s);
  return frame_runs(gt, [&](const vision::StampedPose& g) {
    return occlusion.hides_object(g.t_s, scene.world_T_obj * g.cam_T_obj.inverse());
  });
}

std::string runs_json(const FrameRuns& runs) {
  std::string out = "[";
  for (std::size_t i = 0; i < runs.size(); ++i)
    out += (i ? ", [" : "[") + std::to_string(runs[i].first) + ", " + std::to_string(runs[i].second) + "]";
  return out + "]";
}

// sim_truth.json: how the sequence was made (timing, the head's start angles, the IMU's drawn
// errors, the scene variety, the frames with the whole object in view).
std::string truth_json(const Scenario& s, double exposure_s, int subframes, const SimSummary& summary,
                       const HeadAngles& head0, const ImuRun& imu, const SceneVariety& drawn,
                       const FrameRuns& in_view, const FrameRuns& hidden) {
  std::ostringstream j;
  j << "{\n  \"scenario\": \"" << s.name << "\",\n  \"scene\": \"" << s.scene << "\",\n  \"seed\": " << s.seed
    << ",\n  \"frames\": " << s.frames << ",\n  \"fps\": " << num(s.fps) << ",\n  \"first_frame_s\": "
    << num(s.frame_time_s(0)) << ",\n  \"exposure_s\": " << num(exposure_s) << ",\n  \"blur_subframes\": " << subframes
    << ",\n  \"jerk\": " << num(s.motion == MotionKind::handheld ? s.handheld.jerk : s.walking.jerk) << ",\n  \"peak_body_rate_degps\": " << num(summary.peak_body_rate_degps)
    << ",\n  \"head_deg\": [" << num(head0.pan_rad * rad2deg) << ", " << num(head0.tilt_rad * rad2deg) << "]"
    << ",\n  \"imu\": {\n    \"time\": \"t_device_s = clock_offset_s + (1 + clock_drift) * t_true_s\",\n"
    << "    \"clock_offset_s\": " << num(s.imu.clock_offset_s) << ",\n    \"clock_drift\": " << num(s.imu.clock_drift)
    << ",\n    \"rate_hz\": " << num(s.imu.rate_hz) << ",\n    \"samples\": " << imu.samples.size()
    << ",\n    \"dropped\": " << imu.dropped << ",\n    \"saturated\": " << imu.saturated
    << ",\n    \"gyro_scale\": " << vec(imu.gyro_scale) << ",\n    \"accel_scale\": " << vec(imu.accel_scale)
    << ",\n    \"gyro_bias0_radps\": " << vec(imu.gyro_bias0_radps) << ",\n    \"accel_bias0_mps2\": "
    << vec(imu.accel_bias0_mps2) << "\n  }";
  j << ",\n  \"object_in_view_frames\": " << runs_json(in_view);
  j << ",\n  \"object_hidden_frames\": " << runs_json(hidden);
  // Only with variety or covers, so that a built-in scene's output stays as it always was.
  if (s.variety > 0 || !s.covers.empty()) j << ",\n  \"scene_variety\": " << to_json(drawn, "  ");
  j << "\n}\n";
  return j.str();
}

}  // namespace

std::expected<SimSummary, std::string> write_sequence(const Scenario& scenario, const std::string& out_dir,
                                                      const FrameProgress& progress) {
  // The scene and scenario as they run: the seed's scene variety and the cover boards applied.
  auto made = make_scenario_scene(scenario);
  if (!made) return std::unexpected(made.error());
  const Scenario& s = made->scenario;
  std::optional<Scene> scene(std::move(made->scene));
  auto camera = scenario_camera(s);
  if (!camera) return std::unexpected(camera.error());
  if (auto ok = prepare_dir(out_dir); !ok) return std::unexpected(ok.error());
  const fs::path dir(out_dir);

  const Rig rig = Rig::from_scenario(s, scene->view.target_world, scene->world_T_obj);
  const int subframes = s.blur_subframes.value_or(scene->blur_subframes);
  const double exposure_s = s.exposure_s.value_or(scene->exposure_s);
  const double t_last = s.frame_time_s(s.frames - 1);

  if (auto ok = camera->save((dir / "camera.yaml").string()); !ok) return std::unexpected(ok.error());
  // The scene's CAO file as built into the program (byte for byte sim/scenes/<scene>.cao).
  const auto model_cao = scene_model_cao(s.scene);
  if (auto ok = write_text(dir / "model.cao", model_cao ? std::string(*model_cao) : vision::to_cao(scene->model)); !ok)
    return std::unexpected(ok.error());

  // Ground truth at each frame's mid-exposure (= the frame time), and the perturbed start.
  std::vector<vision::StampedPose> gt;
  std::vector<vision::FrameEntry> frames;
  gt.reserve(static_cast<std::size_t>(s.frames));
  frames.reserve(static_cast<std::size_t>(s.frames));
  for (int i = 0; i < s.frames; ++i) {
    const double t = s.frame_time_s(i);
    gt.push_back({i, t, rig.cam_T_obj(t), {}});
    char name[32];
    std::snprintf(name, sizeof name, "frames/%06d.png", i);
    frames.push_back({i, t, name});
  }
  Random init_rng(s.seed, 31);
  const Eigen::Vector3d dir_t = Eigen::Vector3d(init_rng.normal(), init_rng.normal(), init_rng.normal()).normalized();
  const Eigen::Vector3d axis = Eigen::Vector3d(init_rng.normal(), init_rng.normal(), init_rng.normal()).normalized();
  vision::StampedPose init = gt.front();
  init.cam_T_obj.linear() = Eigen::AngleAxisd(s.init_error_deg / rad2deg, axis).toRotationMatrix() * init.cam_T_obj.linear();
  init.cam_T_obj.translation() += s.init_error_m * dir_t;

  // IMU from true time 0 (before frame 0) to a little after the last frame.
  const ImuRun imu = simulate_imu(s.imu, s.seed, [&rig](double t) { return rig.world_T_cam(t); }, 0.0,
                                  t_last + 0.2);
  std::vector<vision::ImuRecord> measured, truth;
  measured.reserve(imu.samples.size());
  truth.reserve(imu.samples.size());
  for (const ImuSample& x : imu.samples) {
    truth.push_back({x.t_true_s, x.gyro_true_radps, x.accel_true_mps2});
    if (!x.dropped) measured.push_back({x.t_device_s, x.gyro_radps, x.accel_mps2});
  }

  for (auto ok : {vision::write_pose_csv((dir / "gt.csv").string(), gt),
                  vision::write_pose_csv((dir / "init.csv").string(), {init})}) {
    if (!ok) return std::unexpected(ok.error());
  }
  for (auto ok : {vision::write_imu_csv((dir / "imu.csv").string(), measured),
                  vision::write_imu_csv((dir / "imu_true.csv").string(), truth),
                  vision::write_frames_csv((dir / "frames.csv").string(), frames)}) {
    if (!ok) return std::unexpected(ok.error());
  }

  SimSummary summary;
  summary.frames = s.frames;
  summary.duration_s = t_last - s.frame_time_s(0);
  summary.peak_body_rate_degps = peak_angular_rate_degps(rig.body(), s.frame_time_s(0), t_last);
  summary.imu_samples = static_cast<int>(measured.size());
  summary.imu_dropped = imu.dropped;
  summary.imu_saturated = imu.saturated;

  const HeadAngles head0 = rig.head_angles(s.frame_time_s(0));
  const std::string sim_truth =
      truth_json(s, exposure_s, subframes, summary, head0, imu, made->drawn,
                 object_in_view_runs(s, gt, scene->model, *camera), object_hidden_runs(*scene, s, gt));
  if (auto ok = write_text(dir / "sim_truth.json", sim_truth); !ok) return std::unexpected(ok.error());
  if (auto ok = write_text(dir / "scenario.scn", s.text); !ok) return std::unexpected(ok.error());

  // Frames last: the slow part.
  RenderOptions options;
  options.samples_per_subframe = s.antialias_samples;
  options.noise_sigma_dn = s.noise_dn;
  Renderer renderer(std::move(*scene), *camera, options);
  const Scene& rscene = renderer.scene();
  std::vector<std::vector<Eigen::Isometry3d>> occ_poses(static_cast<std::size_t>(subframes));
  std::vector<SubFrame> subs(static_cast<std::size_t>(subframes));
  cv::Mat image;
  const std::vector<int> png_params{cv::IMWRITE_PNG_COMPRESSION, 3};
  for (int i = 0; i < s.frames; ++i) {
    const double t = s.frame_time_s(i);
    for (int k = 0; k < subframes; ++k) {
      // Sub-frames at the centres of equal slices of the exposure, which is centred on t.
      const double tk = t + exposure_s * ((k + 0.5) / subframes - 0.5);
      occluder_poses_at(rscene, s, tk, occ_poses[static_cast<std::size_t>(k)]);
      subs[static_cast<std::size_t>(k)] = {rig.world_T_cam(tk).pose, rscene.world_T_obj, occ_poses[static_cast<std::size_t>(k)]};
    }
    FrameInput input;
    input.t_s = t;
    input.sub_frames = subs;
    input.illumination_gain = s.light_gain(t);
    cv::RNG rng(Random(s.seed, 41, static_cast<std::uint64_t>(i)).next_u64() | 1);
    renderer.render(input, rng, image);
    const std::string path = (dir / frames[static_cast<std::size_t>(i)].file).string();
    if (!cv::imwrite(path, image, png_params)) return std::unexpected("cannot write " + path);
    if (progress) progress(i, s.frames);
  }
  return summary;
}

}  // namespace epichead::sim
