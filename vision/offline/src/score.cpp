#include "epichead/vision/offline/score.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/Geometry>

#include "epichead/geometry/se3.h"

namespace epichead::vision {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Angle of a rotation in degrees; from the quaternion, which stays accurate near zero where
// acos of the trace does not.
double rotation_angle_deg(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return 2.0 * std::atan2(q.vec().norm(), std::abs(q.w())) * 180.0 / std::numbers::pi;
}

// The object points whose reprojection is compared: vertices, or for models without any,
// the circle centres and cylinder axis end points.
std::vector<Eigen::Vector3d> reprojection_points(const CadModel& model) {
  if (!model.vertices.empty()) return model.vertices;
  std::vector<Eigen::Vector3d> points;
  for (const auto& c : model.circles) points.push_back(c.centre_obj);
  for (const auto& c : model.cylinders) {
    points.push_back(c.axis_a_obj);
    points.push_back(c.axis_b_obj);
  }
  return points;
}

// Mean pixel distance of the points projected with both poses, over the points the image
// shows at the true pose: points behind the camera in either pose, or outside the image at the
// true pose, are left out. A room's vertices may lie beside or just in front of the camera,
// where the distortion polynomial (fitted inside the image) sends them to 1e12 px. NaN when no
// point is usable.
double reprojection_error_px(const std::vector<Eigen::Vector3d>& points, const Camera& camera,
                             const Eigen::Isometry3d& gt_T, const Eigen::Isometry3d& est_T) {
  double sum = 0;
  int n = 0;
  for (const auto& p : points) {
    const Eigen::Vector3d a = gt_T * p, b = est_T * p;
    if (!(a.z() > 0) || !(b.z() > 0)) continue;
    const Eigen::Vector2d seen_px = camera.project(a);
    if (!camera.in_image(seen_px)) continue;
    const double d = (seen_px - camera.project(b)).norm();
    if (!std::isfinite(d)) continue;
    sum += d;
    ++n;
  }
  return n > 0 ? sum / n : kNaN;
}

// Mean, median and 95th percentile (linear interpolation between order statistics, as numpy's
// default) of the finite values; NaN when there are none.
ErrorStats stats_of(std::vector<double> values) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  if (values.empty()) return {kNaN, kNaN, kNaN};
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double pos = q * static_cast<double>(values.size() - 1);
    const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  double sum = 0;
  for (double v : values) sum += v;
  return {sum / static_cast<double>(values.size()), quantile(0.5), quantile(0.95)};
}

}  // namespace

Eigen::Matrix3d remove_turn(const Eigen::Matrix3d& R_gt, const Eigen::Matrix3d& R_est, const Eigen::Vector3d& axis) {
  // With q = quat(R_gt^T R_est) = (w, v), the product with (cos(theta/2), axis sin(theta/2)) has
  // scalar part w cos(theta/2) - (v.axis) sin(theta/2), whose magnitude (the cosine of half the
  // error angle) is largest at theta/2 = atan2(-(v.axis), w).
  const Eigen::Quaterniond q(R_gt.transpose() * R_est);
  const double theta = 2.0 * std::atan2(-q.vec().dot(axis), q.w());
  return R_est * Eigen::AngleAxisd(theta, axis).toRotationMatrix();
}

ScoreSummary score_poses(const std::vector<StampedPose>& ground_truth, const std::vector<StampedPose>& estimates,
                         const Camera& camera, const CadModel& model,
                         const std::optional<Eigen::Vector3d>& sym_axis_obj, const ScoreCriterion& criterion,
                         const std::vector<Eigen::Isometry3d>& symmetries_obj) {
  std::optional<Eigen::Vector3d> axis;
  if (sym_axis_obj) {
    if (!sym_axis_obj->allFinite() || sym_axis_obj->norm() < 1e-12)
      throw std::invalid_argument("score_poses: the symmetry axis must be a finite non-zero vector");
    axis = sym_axis_obj->normalized();
  }
  std::unordered_map<int, const StampedPose*> by_frame;
  by_frame.reserve(estimates.size());
  // A frame the tracker itself reported as lost carries no estimate (it echoes its prediction).
  for (const auto& e : estimates)
    if (e.status != "lost") by_frame.try_emplace(e.frame, &e);

  std::vector<const StampedPose*> truth;
  truth.reserve(ground_truth.size());
  for (const auto& g : ground_truth) truth.push_back(&g);
  std::stable_sort(truth.begin(), truth.end(), [](auto* a, auto* b) { return a->frame < b->frame; });

  const std::vector<Eigen::Vector3d> points = reprojection_points(model);
  ScoreSummary summary;
  summary.frames = static_cast<int>(truth.size());
  summary.per_frame.reserve(truth.size());
  std::vector<double> rot, trans, reproj;
  bool in_failure_run = false;
  for (const StampedPose* gt : truth) {
    FrameScore s;
    s.frame = gt->frame;
    s.rotation_deg = s.translation_mm = s.reprojection_px = kNaN;
    const auto it = by_frame.find(gt->frame);
    if (it != by_frame.end()) {
      s.present = true;
      Eigen::Isometry3d est_T = it->second->cam_T_obj;
      const Eigen::Matrix3d R_gt = gt->cam_T_obj.linear();
      for (const auto& S : symmetries_obj) {
        const Eigen::Isometry3d alt = it->second->cam_T_obj * S;
        if (rotation_angle_deg(R_gt.transpose() * alt.linear()) < rotation_angle_deg(R_gt.transpose() * est_T.linear())) est_T = alt;
      }
      if (axis) est_T.linear() = remove_turn(R_gt, est_T.linear(), *axis);
      s.rotation_deg = rotation_angle_deg(R_gt.transpose() * est_T.linear());
      const double translation_m = (est_T.translation() - gt->cam_T_obj.translation()).norm();
      s.translation_mm = 1000.0 * translation_m;
      s.reprojection_px = reprojection_error_px(points, camera, gt->cam_T_obj, est_T);
      s.error_twist = geometry::se3_log(gt->cam_T_obj * est_T.inverse());
      if (axis) {
        // A turn by theta about the line through the object origin c along w moves a point p by
        // theta * (w x p + c x w): the left perturbation (c x w, w).
        const Eigen::Vector3d w = est_T.linear() * *axis;
        s.axis_twist << est_T.translation().cross(w), w;
      }
      s.success = translation_m <= criterion.max_translation_m && s.rotation_deg <= criterion.max_rotation_deg;
      s.success_tight = translation_m <= criterion.tight_translation_m && s.rotation_deg <= criterion.tight_rotation_deg;
      ++summary.present;
      rot.push_back(s.rotation_deg);
      trans.push_back(s.translation_mm);
      reproj.push_back(s.reprojection_px);
    }
    if (s.success) ++summary.succeeded;
    if (s.success_tight) ++summary.succeeded_tight;
    if (!s.success && !in_failure_run) ++summary.losses;
    in_failure_run = !s.success;
    summary.per_frame.push_back(s);
  }
  summary.success_rate = summary.frames > 0 ? static_cast<double>(summary.succeeded) / summary.frames : 0.0;
  summary.success_rate_tight = summary.frames > 0 ? static_cast<double>(summary.succeeded_tight) / summary.frames : 0.0;
  summary.rotation_deg = stats_of(std::move(rot));
  summary.translation_mm = stats_of(std::move(trans));
  summary.reprojection_px = stats_of(std::move(reproj));
  return summary;
}



std::expected<std::vector<CornerObservation>, std::string> read_corners(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::unexpected(path + ": cannot open");
  std::vector<CornerObservation> out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream fields(line);
    CornerObservation c;
    double v[5];
    int n = 0;
    while (n < 5 && fields >> v[n]) ++n;
    if (n == 0 && fields.eof()) continue;  // blank or comment
    std::string rest;
    if (n != 5 || (fields >> rest) || !std::isfinite(v[0] + v[1] + v[2] + v[3] + v[4]))
      return std::unexpected(path + ":" + std::to_string(number) + ": expected X Y Z u v (five numbers)");
    c.p_obj = {v[0], v[1], v[2]};
    c.px = {v[3], v[4]};
    out.push_back(c);
  }
  if (out.empty()) return std::unexpected(path + ": no corners");
  return out;
}

CornerError corner_error(const std::vector<CornerObservation>& corners, const Eigen::Isometry3d& cam_T_obj,
                         const Camera& camera) {
  CornerError e;
  double sum2 = 0;
  for (const auto& c : corners) {
    const Eigen::Vector3d p = cam_T_obj * c.p_obj;
    const double d = p.z() > 0 ? (camera.project(p) - c.px).norm() : std::numeric_limits<double>::infinity();
    sum2 += d * d;
    e.max_px = std::max(e.max_px, d);
  }
  e.rms_px = corners.empty() ? 0.0 : std::sqrt(sum2 / static_cast<double>(corners.size()));
  return e;
}

}  // namespace epichead::vision
