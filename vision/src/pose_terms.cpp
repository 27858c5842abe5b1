#include "pose_terms.h"

#include <algorithm>

#include <Eigen/LU>

#include "epichead/geometry/so3.h"

namespace epichead::vision::detail {

void add_line_cost(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                   const Tukey& k, double& sum) {
  for_each_edgel_chunk(obs, img, xns, focal, &k, false, [&](const EdgelChunk& c, int, int n) {
    for (int q = 0; q < n; ++q) sum += c.rho[q];
  });
}

// A line's residuals depend on the pose only through its image line l, so r_k = f(l, x_k) and
// J_k = (dr_k/dl)^T dl/dxi with one 3x6 dl/dxi per line: the edgels accumulate the 3x3
// sum w (dr/dl)(dr/dl)^T and the 3-vector sum w r dr/dl, and the 6x6 is formed once per line
// (dl^T M dl) instead of once per edgel. The same sums as per-edgel rows, grouped differently
// (round-off only).
void add_line_block(const LineObservation& obs, const LineImage& img, const Eigen::Vector2d* xns, double focal,
                    const Tukey& k, NormalEquations& ne, double shared_sigma_px) {
  const bool shared_errors = shared_sigma_px >= 0;
  const Eigen::Vector3d& l = img.l;
  const double s = img.s;
  // M (column-major, as Eigen's) and v, summed edgel by edgel. No skip at w = 0: a non-finite
  // row must still reach H.
  double m[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0}, v0 = 0, v1 = 0, v2 = 0;
  // For the shared errors: sums of w dr/dl and of w t dr/dl with t the edgel's place along the
  // line (normalised coordinates), of w and w t, and t's extent.
  Eigen::Vector3d s0 = Eigen::Vector3d::Zero(), s1 = Eigen::Vector3d::Zero();
  double w0 = 0, wt = 0, t_min = 0, t_max = 0;
  const Eigen::Vector2d along(-l.y() / s, l.x() / s);
  for_each_edgel_chunk(obs, img, xns, focal, &k, true, [&](const EdgelChunk& chunk, int first, int n) {
    for (int q = 0; q < n; ++q) {
      const double r = chunk.r[q], w = chunk.w[q];
      const double d[3] = {chunk.d0[q], chunk.d1[q], chunk.d2[q]};
      const double wd[3] = {w * d[0], w * d[1], w * d[2]};
      ne.cost += chunk.rho[q];
      for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) m[3 * j + i] += wd[i] * d[j];
      const double wr = w * r;
      v0 += wr * d[0];
      v1 += wr * d[1];
      v2 += wr * d[2];
      ne.wr2 += w * r * r;
      ne.wsum += w;
      if (shared_errors) {
        const Eigen::Vector3d dr_dl(d[0], d[1], d[2]);
        const double t = along.dot(xns[first + q]);
        s0 += w * dr_dl;
        s1 += (w * t) * dr_dl;
        w0 += w;
        wt += w * t;
        t_min = first + q ? std::min(t_min, t) : t;
        t_max = first + q ? std::max(t_max, t) : t;
      }
    }
  });
  const Eigen::Map<const Eigen::Matrix3d> M(m);
  const Eigen::Vector3d v(v0, v1, v2);
  // dl/dxi of l = A x B under a left perturbation of the pose: dA = [I | -[A]x] dxi (same for
  // B), so dl = [A - B]x dt - [l]x dphi (using [B]x[A]x - [A]x[B]x = [B x A]x).
  Eigen::Matrix<double, 3, 6> dl;
  dl.leftCols<3>() = geometry::skew(img.A - img.B);
  dl.rightCols<3>() = -geometry::skew(l);
  ne.H.noalias() += dl.transpose() * M * dl;
  ne.g.noalias() += dl.transpose() * v;
  if (shared_errors && w0 > 0 && t_max > t_min) {
    // The model's error in pixels at the segment's mean depth.
    const double depth = 0.5 * (img.A.z() + img.B.z());
    const double model_px = depth > 0 ? focal * obs.model_error_m / depth : 0.0;
    const double s2 = shared_sigma_px * shared_sigma_px + model_px * model_px;
    // Per pixel: dr is in units of sigma_px. The turn is about the weighted centre.
    const double half = (t_max - t_min) / 2, centre = wt / w0;
    const Vector6d a = dl.transpose() * s0 / obs.sigma_px;
    const Vector6d b = dl.transpose() * (s1 - centre * s0) / (half * obs.sigma_px);
    ne.shared.noalias() += s2 * (a * a.transpose() + b * b.transpose());
  }
}

Eigen::Matrix3d circle_conic_normalized(const ModelCircle& circle, const Eigen::Isometry3d& cam_T_obj) {
  const Eigen::Vector3d c = cam_T_obj * circle.centre_obj;
  const Eigen::Vector3d n = cam_T_obj.linear() * circle.normal_obj.normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  Eigen::Matrix3d Q;
  Q << circle.radius_m * u, circle.radius_m * v, c;
  const Eigen::Matrix3d Qi = Q.inverse();
  return Qi.transpose() * Eigen::Vector3d(1, 1, -1).asDiagonal() * Qi;
}

double PoseTerms::cost(const Eigen::Isometry3d& cam_T_obj, const Tukey& k) const {
  double sum = 0;
  for (std::size_t i = 0; i < problem_.lines.size(); ++i) {
    const LineObservation& obs = problem_.lines[i];
    if (obs.edgels_px.size() < 2 || skip(static_cast<int>(i), Rejected::Skip)) continue;
    add_line_cost(obs, line_image(obs, cam_T_obj), line_edgels(i), focal_, k, sum);
  }
  rows(cam_T_obj, Rejected::Skip, false, [&](double r, const RowJ&, int) { sum += k.rho(r); });
  return sum;
}

void PoseTerms::normal_equations(const Eigen::Isometry3d& cam_T_obj, const Tukey& k, NormalEquations& ne,
                                 double shared_sigma_px) const {
  ne = NormalEquations{};
  for (std::size_t i = 0; i < problem_.lines.size(); ++i) {
    const LineObservation& obs = problem_.lines[i];
    if (obs.edgels_px.size() < 2 || skip(static_cast<int>(i), Rejected::Skip)) continue;
    add_line_block(obs, line_image(obs, cam_T_obj), line_edgels(i), focal_, k, ne, shared_sigma_px);
  }
  rows(cam_T_obj, Rejected::Skip, true, [&](double r, const RowJ& J, int) { ne.add_row(r, J, k); });
}

bool PoseTerms::all_in_front(const Eigen::Isometry3d& cam_T_obj) const {
  for (const auto& obs : problem_.lines)
    if (obs.edgels_px.size() >= 2 && ((cam_T_obj * obs.a_obj).z() <= 0 || (cam_T_obj * obs.b_obj).z() <= 0)) return false;
  for (const auto& obs : problem_.points) if ((cam_T_obj * obs.p_obj).z() <= 0) return false;
  return true;
}

}  // namespace epichead::vision::detail
