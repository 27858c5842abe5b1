#include "epichead/vision/model_symmetry.h"

#include <cmath>

#include <Eigen/Eigenvalues>

namespace epichead::vision {
namespace {

// The principal axes, made definite where two of them share a variance. A body of revolution
// (a can's two rims of 32 facets) has an axis and a plane of equal variance in which the solver
// picks any two directions; the half turn that swaps its ends is found only about a direction
// through a vertex, so one of the pair is turned onto the vertex farthest from the axis. Three
// equal variances (a cube) are left as the solver gives them.
Eigen::Matrix3d principal_axes(const Eigen::Vector3d& variance, Eigen::Matrix3d E, const std::vector<Eigen::Vector3d>& v,
                               const Eigen::Vector3d& c) {
  const double tol = 1e-6 * variance.cwiseAbs().maxCoeff();
  const bool low_pair = std::abs(variance(1) - variance(0)) <= tol, high_pair = std::abs(variance(2) - variance(1)) <= tol;
  if (low_pair == high_pair) return E;
  const int axis = low_pair ? 2 : 0, a = low_pair ? 0 : 1, b = low_pair ? 1 : 2;
  const Eigen::Vector3d n = E.col(axis);
  Eigen::Vector3d far = Eigen::Vector3d::Zero();
  for (const auto& p : v) {
    const Eigen::Vector3d off = (p - c) - n * n.dot(p - c);
    if (off.squaredNorm() > far.squaredNorm()) far = off;
  }
  if (!(far.norm() > 0)) return E;
  E.col(a) = far.normalized();
  E.col(b) = n.cross(E.col(a));
  return E;
}

}  // namespace

std::vector<Eigen::Isometry3d> model_symmetries(const CadModel& model) {
  std::vector<Eigen::Isometry3d> out;
  const auto& v = model.vertices;
  if (v.size() < 3) return out;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : v) c += p;
  c /= static_cast<double>(v.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double extent = 0;
  for (const auto& p : v) {
    cov += (p - c) * (p - c).transpose();
    extent = std::max(extent, (p - c).norm());
  }
  if (!(extent > 0)) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  const Eigen::Matrix3d E = principal_axes(eig.eigenvalues(), eig.eigenvectors(), v, c);
  const double tol = 1e-3 * extent;
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& perm : perms)
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
      for (int i = 0; i < 3; ++i) P(i, perm[i]) = (signs >> i & 1) ? -1.0 : 1.0;
      if (P.determinant() < 0 || P.isIdentity()) continue;
      const Eigen::Matrix3d R = E * P * E.transpose();
      bool maps = true;
      for (std::size_t i = 0; i < v.size() && maps; ++i) {
        const Eigen::Vector3d q = R * (v[i] - c) + c;
        bool hit = false;
        for (const auto& w : v)
          if ((q - w).norm() <= tol) { hit = true; break; }
        maps = hit;
      }
      if (!maps) continue;
      Eigen::Isometry3d S = Eigen::Isometry3d::Identity();
      S.linear() = R;
      S.translation() = c - R * c;
      out.push_back(S);
    }
  return out;
}

namespace {

template <typename Cost>
Eigen::Isometry3d cheapest(const Eigen::Isometry3d& cam_T_obj, const std::vector<Eigen::Isometry3d>& symmetries, Cost cost) {
  Eigen::Isometry3d best = cam_T_obj;
  double best_cost = cost(best);
  for (const Eigen::Isometry3d& S : symmetries) {
    const Eigen::Isometry3d T = cam_T_obj * S;
    if (const double c = cost(T); c < best_cost) {
      best_cost = c;
      best = T;
    }
  }
  return best;
}

}  // namespace

Eigen::Isometry3d symmetric_nearest(const Eigen::Isometry3d& cam_T_obj, const std::vector<Eigen::Isometry3d>& symmetries,
                                    const Eigen::Isometry3d& like) {
  return cheapest(cam_T_obj, symmetries, [&](const Eigen::Isometry3d& T) {
    return Eigen::AngleAxisd(like.linear().transpose() * T.linear()).angle();
  });
}

Eigen::Isometry3d symmetric_upright(const Eigen::Isometry3d& cam_T_obj, const std::vector<Eigen::Isometry3d>& symmetries,
                                    const Eigen::Vector3d& up_obj, const Eigen::Vector3d& up_cam) {
  return cheapest(cam_T_obj, symmetries, [&](const Eigen::Isometry3d& T) { return -(T.linear() * up_obj).dot(up_cam); });
}

double symmetric_turn_rad(const Eigen::Matrix3d& cam_R_a, const Eigen::Matrix3d& cam_R_b,
                          const std::vector<Eigen::Isometry3d>& symmetries, const std::optional<Eigen::Vector3d>& free_axis_obj) {
  auto turn = [&](const Eigen::Matrix3d& b) {
    if (free_axis_obj) {
      const Eigen::Vector3d u = cam_R_a * *free_axis_obj, v = b * *free_axis_obj;
      return std::atan2(u.cross(v).norm(), u.dot(v));
    }
    return Eigen::AngleAxisd(cam_R_a.transpose() * b).angle();
  };
  double best = turn(cam_R_b);
  for (const auto& S : symmetries) best = std::min(best, turn(cam_R_b * S.linear()));
  return best;
}

}  // namespace epichead::vision

