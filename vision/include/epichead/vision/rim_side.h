#pragma once
// Which side of a projected model circle the object is on, from the model's own surfaces, as
// ObjectSide says it for lines. A can's rim seen from above has its cap inside the ellipse and
// its side wall below the front arc; a label band printed just above the bottom rim makes a
// second, stronger ellipse whose inside is the label, not the can's bare strip: comparing the
// side where the object surely is tells them apart, where both sides voting blurs it.
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "epichead/vision/camera.h"
#include "epichead/vision/cao_model.h"
#include "epichead/vision/visibility.h"

namespace epichead::vision {

class RimSides {
 public:
  // Finds, once per model circle, its cap (a face in the circle's plane around its centre)
  // and the side faces that meet it (faces with a vertex on the circle).
  RimSides(const CadModel& model, const Camera& camera);
  // Sets VisibleEllipse::side of every ellipse in `visible` at the pose: Left (the inside,
  // as tracker-line columns run from inside to outside) when the object is inside the ellipse
  // wherever the rim is seen, Right when outside, Both otherwise. Allocates nothing.
  void apply(const Eigen::Isometry3d& cam_T_obj, VisibleModel& visible) const;

 private:
  struct SideFace {
    Eigen::Vector3d rim_point_obj;  // its vertex on the circle
    Eigen::Vector3d into_obj;       // from there into the face (unit)
    Eigen::Vector3d normal_obj;     // outward
  };
  struct Rim {
    int cap = -1;                   // face index, or -1
    Eigen::Vector3d cap_normal_obj = Eigen::Vector3d::Zero();
    std::vector<SideFace> sides;
  };
  const CadModel* model_;
  Camera camera_;
  std::vector<Rim> rims_;  // per model circle
};

}  // namespace epichead::vision
