#include "view_sphere.h"

#include <cmath>
#include <array>
#include <map>
#include <utility>

#include <Eigen/Geometry>

namespace epichead::vision::detail {

std::vector<Eigen::Vector3d> view_directions(int subdivisions) {
  const double p = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, p, 0}, {1, p, 0}, {-1, -p, 0}, {1, -p, 0}, {0, -1, p}, {0, 1, p},
                                    {0, -1, -p}, {0, 1, -p}, {p, 0, -1}, {p, 0, 1}, {-p, 0, -1}, {-p, 0, 1}};
  for (auto& x : v) x.normalize();
  std::vector<std::array<int, 3>> faces = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                           {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                           {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                           {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      if (auto it = mid.find(key); it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int i = static_cast<int>(v.size()) - 1;
      mid.emplace(key, i);
      return i;
    };
    std::vector<std::array<int, 3>> next;
    next.reserve(faces.size() * 4);
    for (const auto& f : faces) {
      const int a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]), c = midpoint(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    faces = std::move(next);
  }
  return v;
}

Eigen::Matrix3d look_rotation(const Eigen::Vector3d& from_obj, double roll_rad) {
  const Eigen::Vector3d z = -from_obj.normalized();  // optical axis, object frame
  const Eigen::Vector3d ref = std::abs(z.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d y = (-(ref - ref.dot(z) * z)).normalized();  // image down = -up
  const Eigen::Vector3d x = y.cross(z);
  Eigen::Matrix3d obj_R_cam;
  obj_R_cam << x, y, z;
  const Eigen::Matrix3d cam_R_obj = obj_R_cam.transpose();
  return Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * cam_R_obj;
}

}  // namespace epichead::vision::detail
