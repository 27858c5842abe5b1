#pragma once
// 3D position of a model circle of known radius from its image ellipse (pinhole camera,
// undistorted pixels): the centre and the plane normal in the camera frame. An ellipse is the
// image of two circles of that radius (two planes cut the viewing cone in circles); the prior
// pose's normal picks one. Uncertainty: the ellipse's parameter covariance from its edge points
// is propagated through the closed form to the centre and normal, for the pose estimator.
#include <expected>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "epichead/vision/camera.h"
#include "epichead/vision/ellipse.h"

namespace epichead::vision {

// Ellipse parameters in the order the covariances use: centre x, centre y, a, b, angle.
using EllipseParams = Eigen::Matrix<double, 5, 1>;
using EllipseCovariance = Eigen::Matrix<double, 5, 5>;
EllipseParams ellipse_params(const Ellipse& e);

// One circle in the camera frame.
struct CircleSolution {
  Eigen::Vector3d centre_cam = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal_cam = Eigen::Vector3d::UnitZ();  // unit
};

struct CirclePose {
  CircleSolution circle;  // the solution chosen by the prior
  CircleSolution other;   // the other one of the two-fold ambiguity
  // Angle between the two solutions' normals: near 0 (circle seen head-on) the choice does not
  // matter; the prior must be better than half of it for the choice to be right.
  double ambiguity_rad = 0;
  // Covariance of (centre_cam, normal_cam) in m and unit-vector components; zero when the
  // ellipse covariance was not given.
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// Both circles of radius radius_m whose image is `ellipse_px`, normals oriented toward the
// camera. Errors: non-positive radius, an invalid ellipse, a conic that is no viewing cone.
std::expected<std::array<CircleSolution, 2>, std::string> circle_solutions(const Ellipse& ellipse_px,
                                                                           const Camera& camera, double radius_m);

// The solution whose normal is nearest (as a line) prior_normal_cam (e.g. R * normal_obj of the
// prior pose), its normal oriented like the prior, and the covariance propagated from
// `ellipse_cov` (see ellipse_covariance) when given.
std::expected<CirclePose, std::string> circle_pose(const Ellipse& ellipse_px, const Camera& camera, double radius_m,
                                                   const Eigen::Vector3d& prior_normal_cam,
                                                   const EllipseCovariance* ellipse_cov = nullptr);

// Covariance of the ellipse parameters fitted to points p[0..n) with noise sigma_px (raised to
// the points' RMS distance when that is larger): sigma^2 (J^T J)^+ of the point distances.
// Directions the points do not constrain (the angle of a circle) get zero variance in the
// pseudo-inverse: they do not move the contour. nullopt for fewer than 5 points.
std::optional<EllipseCovariance> ellipse_covariance(const Ellipse& e, const Eigen::Vector2d* points_px, int n,
                                                    double sigma_px);

}  // namespace epichead::vision
