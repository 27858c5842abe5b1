#pragma once
// Robust pose from 2D lines (edgels against projected model lines), 2D junctions, ellipse
// edge points of model circles and optional 3D junctions: iteratively reweighted
// Levenberg-Marquardt on SE(3) with a Tukey kernel, outlier flags per feature and the
// pose covariance. The solver allocates nothing once the problem's buffers have grown.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/revolution_axis.h"

namespace epichead::vision {

// Edgels (pixels) that belong to the image of the model segment a_obj-b_obj.
struct LineObservation {
  int feature = -1;  // caller's id (a model edge index)
  Eigen::Vector3d a_obj = Eigen::Vector3d::Zero(), b_obj = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector2d> edgels_px;
  double sigma_px = 1.0;  // expected edgel noise
  // The model's own error at this edge, in metres (1-sigma), shared by all its edgels: e.g. the
  // facets of a smooth body (RevolutionAxis::facet_sagitta_m). Adds to
  // PoseOptions::line_shared_sigma_px, scaled to pixels at the edge's depth.
  double model_error_m = 0;
};

// A model vertex seen at a pixel (a junction from intersecting fitted lines).
struct PointObservation {
  int feature = -1;
  Eigen::Vector3d p_obj = Eigen::Vector3d::Zero();
  Eigen::Vector2d px = Eigen::Vector2d::Zero();
  double sigma_px = 1.0;
};

// Edge points (pixels) on the image of a model circle.
struct EllipseObservation {
  int feature = -1;
  ModelCircle circle;
  std::vector<Eigen::Vector2d> points_px;
  double sigma_px = 1.0;
};

// A model vertex measured in 3D in the camera frame by another sensor.
struct Point3dObservation {
  int feature = -1;
  Eigen::Vector3d p_obj = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_cam = Eigen::Vector3d::Zero();
  double sigma_m = 0.005;
};

struct PoseProblem {
  std::vector<LineObservation> lines;
  std::vector<PointObservation> points;
  std::vector<EllipseObservation> ellipses;
  std::vector<Point3dObservation> points_3d;
  // A body of revolution's axis: the turn about it is left at the prior (the features of a
  // smooth surface modelled by facets do not show it) and the covariance gives it
  // free_turn_sigma_rad. Unset for other models.
  std::optional<RevolutionAxis> free_turn;
  double free_turn_sigma_rad = 1.0;
  // Empties the problem (free_turn stays); the vectors keep their capacity for the next frame.
  void clear();
};

struct PoseOptions {
  int max_iterations = 20;            // Levenberg-Marquardt iterations per round
  int max_rejection_rounds = 8;      // rounds of re-solving after rejecting the worst outlier feature
  double tukey_c = 4.685;            // Tukey biweight constant, in units of the robust residual scale
  double min_scale_px = 1.0;         // floor of the robust scale, in units of each feature's sigma
  double outlier_sigma = 3.0;        // a feature whose RMS residual exceeds this many scales is an outlier
  double max_condition = 1e10;       // larger condition number of the normal matrix = degenerate
  double convergence_step = 1e-10;   // stop when the update's norm falls below this
  // Floor of the residual noise the covariance is scaled by, in units of each feature's sigma.
  double min_noise_sigma = 0.25;
  // The error every edgel of a line shares, in pixels (1-sigma), both as a shift of the whole
  // line and as a turn moving its ends: a CAD model off by a millimetre and a blurred edge's
  // bias do not average out over a line's edgels the way independent noise does (a line's
  // model_error_m adds to it). It replaced a flat x10 on the covariance: chosen on the
  // development seeds for a mean NEES near its degrees of freedom (docs/fusion.md, "Honest
  // vision covariance"). 0: edgels independent.
  double line_shared_sigma_px = 0.5;
};

enum class PoseStatus {
  Ok,
  TooFewFeatures,  // fewer than three constraining features
  Degenerate,      // the features do not fix all six degrees of freedom
  Diverged,        // non-finite values or the object went behind the camera
};

const char* to_string(PoseStatus status);

// Per feature, in the order lines, points, ellipses, points_3d.
struct FeatureResidual {
  int feature = -1;
  double rms = 0;       // RMS residual (pixels; metres for 3D points)
  bool inlier = true;
};

struct PoseResult {
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  // Covariance of the left perturbation (translation, rotation) applied to cam_T_obj
  // (geometry/pose_covariance.h).
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
  PoseStatus status = PoseStatus::Ok;
  std::string reason;  // for a status other than Ok
  int iterations = 0;
  double scale_px = 0;  // robust residual scale at the end
  int inliers = 0, outliers = 0;
  std::vector<FeatureResidual> residuals;
};

class PoseEstimator {
 public:
  PoseEstimator(const Camera& camera, const PoseOptions& options = {});
  // Refines `prior_cam_T_obj` on the problem's features; `out` is reused between calls.
  void estimate(const PoseProblem& problem, const Eigen::Isometry3d& prior_cam_T_obj, PoseResult& out);
  // Sizes the scratch buffers for problems of up to `slots` features (lines, points and
  // ellipses) and `observations` edgels and ellipse points, so that estimate() does not grow
  // them on the first frame that sees more of the model than any before.
  void reserve(std::size_t slots, std::size_t observations);

 private:
  Camera camera_;
  PoseOptions options_;
  std::vector<double> residual_scratch_;  // |r| of every residual, for the robust scale
  std::vector<unsigned char> rejected_;                    // per feature slot
  std::vector<double> feature_sq_, feature_n_;            // per feature slot: RMS, residual count
  std::vector<Eigen::Vector2d> normalized_;               // undistorted edgels and ellipse points
  std::vector<std::size_t> offsets_;                      // per line, then per ellipse: start in normalized_
};

// The covariance of a starting pose given by hand or by init.csv: 1 cm and 1 degree (1-sigma per
// axis), in the order of geometry/pose_covariance.h.
Eigen::Matrix<double, 6, 6> initial_pose_covariance();

}  // namespace epichead::vision
