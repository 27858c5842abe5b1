#pragma once
// A model that is a body of revolution — a cone, a can or a bowl modelled, as CAO users do, by
// rings of facets plus its rims as circles — has a turn about its axis that its edges cannot
// show: the real surface is smooth, and its contour in the image does not move when the object
// turns about itself (the facet edge the model puts on the contour does, which is the model's
// approximation, not the object). The pose estimator leaves that turn to the prior and says
// in the covariance that it is unknown (pose_estimator.h, PoseProblem::free_turn).
#include <optional>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/cao_model.h"

namespace epichead::vision {

struct RevolutionAxis {
  Eigen::Vector3d point_obj = Eigen::Vector3d::Zero();      // a point on the axis
  Eigen::Vector3d direction_obj = Eigen::Vector3d::UnitZ();  // unit
  // How far the facets lie from the smooth body they stand for, at most: a ring of n vertices
  // at radius r is a polygon whose sides come r (1 - cos(pi / n)) inside the circle. The edges
  // of such a model, and the contour the real surface shows, are this far apart, wherever the
  // object is turned.
  double facet_sagitta_m = 0;
};

// The axis when the whole model is invariant under turns about it up to its facets: every
// circle and cylinder lies on the axis, and the vertices form rings about it, each of at least
// `min_ring_vertices` vertices evenly spaced in angle (a box, 4 per ring, is not a body of
// revolution; 8 facets or more approximate one). Needs at least one circle or cylinder to
// propose the axis; nothing otherwise.
std::optional<RevolutionAxis> find_revolution_axis(const CadModel& model, int min_ring_vertices = 8);

// The same turn as a left perturbation of cam_T_obj (translation, rotation), unit rotation:
// turning the object by theta about the axis is exp(theta * u) * cam_T_obj to first order.
Eigen::Matrix<double, 6, 1> revolution_twist(const RevolutionAxis& axis, const Eigen::Isometry3d& cam_T_obj);

}  // namespace epichead::vision
