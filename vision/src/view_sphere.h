#pragma once
// Viewpoints for detection templates: directions on the unit sphere from a subdivided
// icosahedron (nearly even spacing), and the camera rotation that looks along one of them
// with a given turn about the line of sight.
#include <vector>

#include <Eigen/Core>

namespace epichead::vision::detail {

// Unit directions (object frame) from which the camera looks at the object: 12 for 0
// subdivisions, then 10 * 4^n + 2.
std::vector<Eigen::Vector3d> view_directions(int subdivisions);

// The rotation camera <- object of a camera placed on `from_obj` (unit, object frame, pointing
// from the object to the camera) looking at the object, turned by roll_rad about its optical
// axis. Roll 0 puts the object's z axis (or x, when looking along z) upward in the image
// where it can; any fixed choice works since every roll is sampled.
Eigen::Matrix3d look_rotation(const Eigen::Vector3d& from_obj, double roll_rad);

}  // namespace epichead::vision::detail
