// Robust pose by iteratively reweighted Levenberg-Marquardt on SE(3).
//
// All residuals are normalised by their feature's sigma, so lines, junctions, ellipse points
// and 3D points mix in one cost. The normal equations are accumulated row by row into a 6x6
// system (no Jacobian matrix is stored), which keeps the solver allocation-free.
//
// Line residual: the signed distance of an edgel from the projected model line, computed in
// undistorted normalised coordinates (where a 3D line stays straight) and scaled to pixels by
// the focal length. With l = A_cam x B_cam (the line through the two projected end points,
// homogeneous), r = l . x / |l_xy|.
#include "epichead/vision/pose_estimator.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Householder>
#include <Eigen/LU>
#include <Eigen/QR>

#include "epichead/geometry/pose_covariance.h"
#include "epichead/geometry/se3.h"
#include "epichead/geometry/so3.h"

namespace epichead::vision {
namespace {

using geometry::apply_left;
using geometry::left_point_jacobian;
using geometry::Matrix6d;
using geometry::skew;
using geometry::Vector6d;
using RowJ = Eigen::Matrix<double, 1, 6>;

// The conic of a circle's image in normalised coordinates (inside negative).
Eigen::Matrix3d circle_conic_normalized(const ModelCircle& circle, const Eigen::Isometry3d& cam_T_obj) {
  const Eigen::Vector3d c = cam_T_obj * circle.centre_obj;
  const Eigen::Vector3d n = cam_T_obj.linear() * circle.normal_obj.normalized();
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  Eigen::Matrix3d Q;
  Q << circle.radius_m * u, circle.radius_m * v, c;
  const Eigen::Matrix3d Qi = Q.inverse();
  return Qi.transpose() * Eigen::Vector3d(1, 1, -1).asDiagonal() * Qi;
}

// First-order geometric distance of x from the conic C (normalised coordinates).
double conic_distance(const Eigen::Matrix3d& C, const Eigen::Vector2d& x) {
  const Eigen::Vector3d h(x.x(), x.y(), 1);
  const Eigen::Vector3d g = C * h;
  const double grad = 2 * std::hypot(g.x(), g.y());
  return grad > 0 ? h.dot(g) / grad : 0.0;
}

double tukey_weight(double u, double c) {
  if (std::abs(u) >= c) return 0;
  const double t = 1 - (u / c) * (u / c);
  return t * t;
}

// rho_max = c^2 / 6, hoisted out of the residual loops by the caller (the same value).
double tukey_rho(double r, double c, double rho_max) {
  if (std::abs(r) >= c) return rho_max;
  const double t = 1 - (r / c) * (r / c);
  return rho_max * (1 - t * t * t);
}

// The directions a step may take: all six, or the five orthogonal to a body of revolution's
// turn (its twist at the pose, unit length). Any complement of the turn reaches the same
// poses up to that turn; the orthogonal one keeps the solve well conditioned.
struct StepBasis {
  Eigen::Matrix<double, 6, 6> B = Eigen::Matrix<double, 6, 6>::Identity();  // first `dims` columns used
  Vector6d turn = Vector6d::Zero();  // the free turn's twist (rotation part unit), or zero
  int dims = 6;
};

StepBasis step_basis(const PoseProblem& problem, const Eigen::Isometry3d& pose) {
  StepBasis b;
  if (!problem.free_turn) return b;
  b.turn = revolution_twist(*problem.free_turn, pose);
  if (!b.turn.allFinite()) return StepBasis{};
  // Householder: Q's first column is along the turn, the other five span its complement.
  const Eigen::Matrix<double, 6, 6> Q = Eigen::HouseholderQR<Vector6d>(b.turn.normalized()).householderQ();
  b.B.leftCols<5>() = Q.rightCols<5>();
  b.dims = 5;
  return b;
}

// Solves (H + lambda diag(H)) step = -g within the basis's directions.
Vector6d damped_step(const StepBasis& b, const Matrix6d& H, const Vector6d& g, double lambda) {
  if (b.dims == 6) {
    Matrix6d A = H;
    A.diagonal() += lambda * H.diagonal().cwiseMax(1e-9);
    return -A.ldlt().solve(g);
  }
  const Eigen::Matrix<double, 6, 5> B = b.B.leftCols<5>();
  Eigen::Matrix<double, 5, 5> A = B.transpose() * H * B;
  A.diagonal() += lambda * A.diagonal().cwiseMax(1e-9);
  return -B * A.ldlt().solve(B.transpose() * g);
}

double median_in_place(std::vector<double>& v) {
  if (v.empty()) return 0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

void PoseProblem::clear() {
  lines.clear();
  points.clear();
  ellipses.clear();
  points_3d.clear();
}

const char* to_string(PoseStatus status) {
  switch (status) {
    case PoseStatus::Ok: return "ok";
    case PoseStatus::TooFewFeatures: return "too_few_features";
    case PoseStatus::Degenerate: return "degenerate";
    case PoseStatus::Diverged: return "diverged";
  }
  return "unknown";
}

Eigen::Matrix<double, 6, 6> initial_pose_covariance() { return geometry::diagonal_pose_covariance(0.01, 0.0174533); }

PoseEstimator::PoseEstimator(const Camera& camera, const PoseOptions& options) : camera_(camera), options_(options) {
  residual_scratch_.reserve(4096);
}

void PoseEstimator::reserve(std::size_t slots, std::size_t observations) {
  rejected_.reserve(slots);
  feature_sq_.reserve(slots);
  feature_n_.reserve(slots);
  offsets_.reserve(slots);
  normalized_.reserve(observations);
}

void PoseEstimator::estimate(const PoseProblem& problem, const Eigen::Isometry3d& prior, PoseResult& out) {
  out.cam_T_obj = prior;
  out.status = PoseStatus::Ok;
  out.reason.clear();
  out.iterations = 0;  // LM iterations over all rounds
  out.inliers = out.outliers = 0;
  out.residuals.clear();
  const double focal = 0.5 * (camera_.intrinsics().fx_px + camera_.intrinsics().fy_px);

  int features = 0, dims = 0;
  for (const auto& l : problem.lines) if (l.edgels_px.size() >= 2) { ++features; dims += 2; }
  features += static_cast<int>(problem.points.size());
  dims += 2 * static_cast<int>(problem.points.size());
  for (const auto& e : problem.ellipses) if (e.points_px.size() >= 5) { ++features; dims += 5; }
  features += static_cast<int>(problem.points_3d.size());
  dims += 3 * static_cast<int>(problem.points_3d.size());
  if (features < 3 || dims < 6) {
    out.status = PoseStatus::TooFewFeatures;
    out.reason = std::to_string(features) + " usable features (need 3 or more)";
    return;
  }

  const std::size_t slots = problem.lines.size() + problem.points.size() + problem.ellipses.size() + problem.points_3d.size();
  // Undistort every edgel and ellipse point once: the residuals are visited several times per
  // iteration, and undistortion is iterative.
  normalized_.clear();
  offsets_.clear();
  for (const auto& obs : problem.lines) {
    offsets_.push_back(normalized_.size());
    for (const auto& q : obs.edgels_px) normalized_.push_back(camera_.pixel_to_normalized(q));
  }
  for (const auto& obs : problem.ellipses) {
    offsets_.push_back(normalized_.size());
    for (const auto& q : obs.points_px) normalized_.push_back(camera_.pixel_to_normalized(q));
  }
  rejected_.assign(slots, 0);
  bool visit_rejected = false;  // true while measuring every feature, rejected ones included
  auto skip = [&](int slot) { return !visit_rejected && rejected_[slot]; };

  // Visits the line features: per line, its slot, the end points A, B in the camera, the image
  // line l = A x B, s = |l_xy| and the line's undistorted edgels; skips rejected features.
  auto visit_lines = [&](const Eigen::Isometry3d& pose, auto&& fn) {
    int slot = 0;
    for (std::size_t i = 0; i < problem.lines.size(); ++i, ++slot) {
      const LineObservation& obs = problem.lines[i];
      if (obs.edgels_px.size() < 2 || skip(slot)) continue;
      const Eigen::Vector3d A = pose * obs.a_obj, B = pose * obs.b_obj;
      const Eigen::Vector3d l = A.cross(B);
      fn(obs, slot, A, B, l, std::hypot(l.x(), l.y()), normalized_.data() + offsets_[i]);
    }
  };
  // The residual of an edgel x (undistorted, normalised) from the line l.
  auto line_residual = [focal](const LineObservation& obs, const Eigen::Vector3d& l, double s, const Eigen::Vector2d& xn) {
    return focal * l.dot(Eigen::Vector3d(xn.x(), xn.y(), 1)) / s / obs.sigma_px;
  };
  // Visits every residual (normalised by its sigma) with its feature slot, skipping rejected
  // features. Jacobian rows (want_jacobian) are given for every feature but lines, whose normal
  // equations normal_equations() accumulates per line; with want_jacobian false, J is untouched.
  auto visit = [&](const Eigen::Isometry3d& pose, bool want_jacobian, auto&& fn) {
    if (!want_jacobian) {
      visit_lines(pose, [&](const LineObservation& obs, int slot, const Eigen::Vector3d&, const Eigen::Vector3d&,
                            const Eigen::Vector3d& l, double s, const Eigen::Vector2d* xns) {
        const RowJ J;
        for (std::size_t k = 0; k < obs.edgels_px.size(); ++k) fn(line_residual(obs, l, s, xns[k]), J, slot);
      });
    }
    int slot = static_cast<int>(problem.lines.size());
    std::size_t list = problem.lines.size();  // index into offsets_: lines, then ellipses
    for (const auto& obs : problem.points) {
      if (skip(slot)) { ++slot; continue; }
      const Eigen::Vector3d X = pose * obs.p_obj;
      const Eigen::Vector2d xn(X.x() / X.z(), X.y() / X.z());
      const Eigen::Vector2d r = (camera_.normalized_to_pixel(xn) - obs.px) / obs.sigma_px;
      Eigen::Matrix<double, 2, 6> J2;
      if (want_jacobian) {
        Eigen::Matrix<double, 2, 3> dn;
        dn << 1 / X.z(), 0, -X.x() / (X.z() * X.z()), 0, 1 / X.z(), -X.y() / (X.z() * X.z());
        J2 = camera_.normalized_to_pixel_jacobian(xn) * dn * left_point_jacobian(X) / obs.sigma_px;
      }
      fn(r.x(), RowJ(J2.row(0)), slot);
      fn(r.y(), RowJ(J2.row(1)), slot);
      ++slot;
    }
    for (const auto& obs : problem.ellipses) {
      const Eigen::Vector2d* xns = normalized_.data() + offsets_[list++];
      if (obs.points_px.size() < 5 || skip(slot)) { ++slot; continue; }
      // Numerical Jacobian: six perturbed conics per ellipse, shared by all its points.
      const Eigen::Matrix3d C = circle_conic_normalized(obs.circle, pose);
      Eigen::Matrix3d Cd[6];
      constexpr double h = 1e-6;
      if (want_jacobian) {
        for (int k = 0; k < 6; ++k) {
          Vector6d xi = Vector6d::Zero();
          xi[k] = h;
          Cd[k] = circle_conic_normalized(obs.circle, apply_left(xi, pose));
        }
      }
      for (std::size_t k = 0; k < obs.points_px.size(); ++k) {
        const Eigen::Vector2d& xn = xns[k];
        const double r = focal * conic_distance(C, xn) / obs.sigma_px;
        RowJ J;
        if (want_jacobian)
          for (int k = 0; k < 6; ++k) J[k] = (focal * conic_distance(Cd[k], xn) / obs.sigma_px - r) / h;
        fn(r, J, slot);
      }
      ++slot;
    }
    for (const auto& obs : problem.points_3d) {
      if (skip(slot)) { ++slot; continue; }
      const Eigen::Vector3d X = pose * obs.p_obj;
      const Eigen::Vector3d r = (X - obs.p_cam) / obs.sigma_m;
      Eigen::Matrix<double, 3, 6> J3;
      if (want_jacobian) J3 = left_point_jacobian(X) / obs.sigma_m;
      for (int i = 0; i < 3; ++i) fn(r[i], RowJ(J3.row(i)), slot);
      ++slot;
    }
  };

  // Weighted normal equations H = sum w J^T J, g = sum w J^T r with Tukey weights at kernel
  // width c, plus sum w r^2 and sum w. A line's residuals depend on the pose only through its
  // image line l, so r_k = f(l, x_k) and J_k = (dr_k/dl)^T dl/dxi with one 3x6 dl/dxi per line:
  // the edgels accumulate the 3x3 sum w (dr/dl)(dr/dl)^T and the 3-vector sum w r dr/dl, and
  // the 6x6 is formed once per line (dl^T M dl) instead of once per edgel. The same sums,
  // grouped differently (round-off only). `cost` is Tukey's cost at the pose, summed in the
  // order of visit() (so equal to weighted_cost() below): the LM step test needs it anyway.
  auto normal_equations = [&](const Eigen::Isometry3d& pose, double c, Matrix6d& H, Vector6d& g, double& wr2, double& wsum,
                              double& cost) {
    H.setZero();
    g.setZero();
    wr2 = 0;
    wsum = 0;
    cost = 0;
    const double rho_max = c * c / 6;
    visit_lines(pose, [&](const LineObservation& obs, int, const Eigen::Vector3d& A, const Eigen::Vector3d& B,
                          const Eigen::Vector3d& l, double s, const Eigen::Vector2d* xns) {
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      for (std::size_t q = 0; q < obs.edgels_px.size(); ++q) {
        const double r = line_residual(obs, l, s, xns[q]);
        const double w = tukey_weight(r, c);  // no skip at w = 0: a non-finite row must still reach H
        cost += tukey_rho(r, c, rho_max);
        const Eigen::Vector3d x(xns[q].x(), xns[q].y(), 1);
        const double ldx = l.dot(x);
        // dr/dl, the same expression (and values) as the per-edgel Jacobian had.
        const Eigen::Vector3d dr_dl = (x / s - ldx / (s * s * s) * Eigen::Vector3d(l.x(), l.y(), 0)) * focal / obs.sigma_px;
        M.noalias() += (w * dr_dl) * dr_dl.transpose();
        v += (w * r) * dr_dl;
        wr2 += w * r * r;
        wsum += w;
      }
      // dl/dxi of l = A x B under a left perturbation of the pose: dA = [I | -[A]x] dxi (same for
      // B), so dl = [A - B]x dt - [l]x dphi (using [B]x[A]x - [A]x[B]x = [B x A]x).
      Eigen::Matrix<double, 3, 6> dl;
      dl.leftCols<3>() = skew(A - B);
      dl.rightCols<3>() = -skew(l);
      H.noalias() += dl.transpose() * M * dl;
      g.noalias() += dl.transpose() * v;
    });
    visit(pose, true, [&](double r, const RowJ& J, int) {
      const double w = tukey_weight(r, c);
      H.noalias() += w * J.transpose() * J;
      g.noalias() += w * J.transpose() * r;
      wr2 += w * r * r;
      wsum += w;
      cost += tukey_rho(r, c, rho_max);
    });
  };

  // The observed segments must stay in front of the camera. Only lines with edgels count: a
  // caller may keep empty slots for every model edge, and an unseen edge may well run behind
  // the camera (a room's wall edge), which would otherwise refuse every step.
  auto all_in_front = [&](const Eigen::Isometry3d& pose) {
    for (const auto& obs : problem.lines)
      if (obs.edgels_px.size() >= 2 && ((pose * obs.a_obj).z() <= 0 || (pose * obs.b_obj).z() <= 0)) return false;
    for (const auto& obs : problem.points) if ((pose * obs.p_obj).z() <= 0) return false;
    return true;
  };

  // Robust scale from the median absolute residual at the current pose.
  auto robust_scale = [&](const Eigen::Isometry3d& pose) {
    residual_scratch_.clear();
    visit(pose, false, [&](double r, const RowJ&, int) { residual_scratch_.push_back(std::abs(r)); });
    return std::max(options_.min_scale_px, 1.4826 * median_in_place(residual_scratch_));
  };

  feature_sq_.assign(slots, 0.0);
  feature_n_.assign(slots, 0.0);
  // Per-feature normalised RMS at `pose` over every feature (rejected ones too).
  auto feature_rms = [&](const Eigen::Isometry3d& pose) {
    std::fill(feature_sq_.begin(), feature_sq_.end(), 0.0);
    std::fill(feature_n_.begin(), feature_n_.end(), 0.0);
    visit_rejected = true;
    visit(pose, false, [&](double r, const RowJ&, int slot) { feature_sq_[slot] += r * r; feature_n_[slot] += 1; });
    visit_rejected = false;
    for (std::size_t i = 0; i < slots; ++i) feature_sq_[i] = feature_n_[i] > 0 ? std::sqrt(feature_sq_[i] / feature_n_[i]) : 0;
  };

  Eigen::Isometry3d pose = prior;
  double scale = 1;
  Matrix6d H = Matrix6d::Zero();
  // Rounds of IRLS; after each, whole features whose RMS residual is far beyond the robust
  // scale are rejected (a wrong candidate line moves all its edgels together, which a
  // per-residual kernel alone can average into a wrong compromise), and the pose is re-solved.
  // Graduated non-convexity: the kernel width starts at what the residuals of the prior need
  // (robust scale from the MAD) and shrinks each iteration toward the width the features'
  // sigmas call for. Taking the MAD at every iteration instead lets a pose biased by many
  // outliers inflate its own scale and stay there.
  const double c_floor = options_.tukey_c * options_.min_scale_px;
  double c = std::max(c_floor, options_.tukey_c * robust_scale(pose));
  for (int round = 0; round < options_.max_rejection_rounds; ++round) {
  double lambda = 1e-3;
  for (int it = 0; it < options_.max_iterations; ++it) {
    out.iterations += 1;
    Vector6d g;
    double unused_wr2 = 0, unused_wsum = 0, base = 0;
    normal_equations(pose, c, H, g, unused_wr2, unused_wsum, base);
    if (!H.allFinite() || !g.allFinite()) {
      out.status = PoseStatus::Diverged;
      out.reason = "non-finite residuals or Jacobian";
      out.cam_T_obj = prior;
      return;
    }
    // Tukey's robust cost at the scale of this iteration: a step is taken only if it lowers it
    // below `base`, the cost at the current pose (summed by normal_equations above).
    auto weighted_cost = [&](const Eigen::Isometry3d& p) {
      double sum = 0;
      const double rho_max = c * c / 6;
      visit(p, false, [&](double r, const RowJ&, int) { sum += tukey_rho(r, c, rho_max); });
      return sum;
    };
    bool improved = false;
    Vector6d step = Vector6d::Zero();
    const StepBasis basis = step_basis(problem, pose);
    for (int tries = 0; tries < 8; ++tries) {
      step = damped_step(basis, H, g, lambda);
      if (!step.allFinite()) break;
      const Eigen::Isometry3d candidate = apply_left(step, pose);
      if (all_in_front(candidate) && weighted_cost(candidate) <= base) {
        pose = candidate;
        lambda = std::max(1e-7, lambda / 10);
        improved = true;
        break;
      }
      lambda *= 10;
    }
    const bool at_floor = c <= c_floor;
    c = std::max(c_floor, c / 1.5);
    if (at_floor && (!improved || step.norm() < options_.convergence_step)) break;
  }
  scale = std::max(options_.min_scale_px, robust_scale(pose));
  feature_rms(pose);
  // Reject the outliers among the worst: every feature beyond the threshold whose RMS is at
  // least half the worst one's. Not all beyond the threshold at once, since one gross outlier can
  // make good features look bad until it is gone; not strictly one at a time either, since
  // several wrong candidates in one frame would each cost a full re-solve.
  double worst_rms = options_.outlier_sigma * scale;
  int remaining = 0;
  for (std::size_t i = 0; i < slots; ++i) {
    if (rejected_[i] || feature_n_[i] == 0) continue;
    ++remaining;
    worst_rms = std::max(worst_rms, feature_sq_[i]);
  }
  const double cut = std::max(options_.outlier_sigma * scale, 0.5 * worst_rms);
  int rejected_now = 0;
  for (std::size_t i = 0; i < slots && remaining - rejected_now > 3; ++i) {
    if (rejected_[i] || feature_n_[i] == 0 || !(feature_sq_[i] > cut)) continue;
    rejected_[i] = 1;
    ++rejected_now;
  }
  if (rejected_now == 0) break;
  }

  // Final weights, degeneracy check, covariance and per-feature residuals at the solution.
  scale = std::max(options_.min_scale_px, robust_scale(pose));
  c = options_.tukey_c * scale;
  double wr2 = 0, wsum = 0, unused_cost = 0;
  Vector6d unused_g;
  normal_equations(pose, c, H, unused_g, wr2, wsum, unused_cost);
  out.cam_T_obj = pose;
  out.scale_px = scale;
  // Degeneracy and covariance within the directions the features are asked to fix: with a free
  // turn, H restricted to its complement, and the turn's own variance added along its twist.
  const StepBasis basis = step_basis(problem, pose);
  Matrix6d H_fixed = H;
  if (basis.dims < 6) {
    // The 5x5 problem padded with its mean eigenvalue: the padding changes neither extreme.
    const Eigen::Matrix<double, 6, 5> B = basis.B.leftCols<5>();
    H_fixed.setZero();
    H_fixed.topLeftCorner<5, 5>() = B.transpose() * H * B;
    H_fixed(5, 5) = H_fixed.topLeftCorner<5, 5>().trace() / 5;
  }
  Eigen::SelfAdjointEigenSolver<Matrix6d> eig(H_fixed);
  const double max_ev = eig.eigenvalues().maxCoeff(), min_ev = eig.eigenvalues().minCoeff();
  if (!(min_ev > 0) || max_ev / min_ev > options_.max_condition) {
    out.status = PoseStatus::Degenerate;
    const Vector6d weak = basis.B * eig.eigenvectors().col(0);
    int axis = 0;
    weak.cwiseAbs().maxCoeff(&axis);
    static const char* names[6] = {"x translation", "y translation", "z translation", "x rotation", "y rotation", "z rotation"};
    out.reason = std::string("features do not constrain the pose; weakest direction mostly ") + names[axis];
  }
  // The edgel noise as the residuals show it (each feature's sigma_px is a unit, not a
  // measurement), but not below min_noise_sigma: a rendered edge can fit to a tenth of a pixel,
  // where the model's own errors are larger (a floor of a whole pixel overstated the
  // uncertainty ~10x on sharp edges: vision NIS medians of 0.05 where 5.3 is consistent).
  const double floor2 = options_.min_noise_sigma * options_.min_noise_sigma;
  const double sigma2 = std::max(floor2, wsum > basis.dims ? wr2 / (wsum - basis.dims) : 1.0);
  if (out.status != PoseStatus::Ok) {
    out.covariance = Matrix6d::Identity() * 1e6;
  } else if (basis.dims == 6) {
    out.covariance = sigma2 * H.inverse();
  } else {
    const Eigen::Matrix<double, 6, 5> B = basis.B.leftCols<5>();
    const Eigen::Matrix<double, 5, 5> H5 = H_fixed.topLeftCorner<5, 5>();
    const double s = problem.free_turn_sigma_rad;
    out.covariance = sigma2 * B * H5.inverse() * B.transpose() + (s * s) * basis.turn * basis.turn.transpose();
  }

  // Per-feature RMS (pixels for image features, metres for 3D points) and inlier flags.
  feature_rms(pose);
  out.residuals.resize(slots);
  std::size_t slot = 0;
  auto finish = [&](int feature, double sigma) {
    FeatureResidual& fr = out.residuals[slot];
    fr.feature = feature;
    fr.inlier = feature_n_[slot] > 0 && !rejected_[slot] && feature_sq_[slot] <= options_.outlier_sigma * scale;
    fr.rms = feature_sq_[slot] * sigma;
    (fr.inlier ? out.inliers : out.outliers) += 1;
    ++slot;
  };
  for (const auto& o : problem.lines) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.points) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.ellipses) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.points_3d) finish(o.feature, o.sigma_m);
}

}  // namespace epichead::vision
