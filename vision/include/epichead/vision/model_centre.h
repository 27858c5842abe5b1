#pragma once
// The centre of a model: the mean of its vertices (the origin for a model without any). What
// fixation keeps in the middle of the image, what sim-run measures that centring by, and the
// point a detected pose is levelled about.
#include <Eigen/Core>

#include "epichead/vision/cao_model.h"

namespace epichead::vision {

Eigen::Vector3d model_centre(const CadModel& model);

}  // namespace epichead::vision
