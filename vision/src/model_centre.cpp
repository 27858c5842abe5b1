#include "epichead/vision/model_centre.h"

namespace epichead::vision {

Eigen::Vector3d model_centre(const CadModel& model) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& v : model.vertices) sum += v;
  return model.vertices.empty() ? sum : Eigen::Vector3d(sum / static_cast<double>(model.vertices.size()));
}

}  // namespace epichead::vision
