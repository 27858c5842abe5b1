#include "epichead/vision/offline/model_symmetry.h"

#include <Eigen/Eigenvalues>

namespace epichead::vision {

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
  const Eigen::Matrix3d E = eig.eigenvectors();
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

}  // namespace epichead::vision
