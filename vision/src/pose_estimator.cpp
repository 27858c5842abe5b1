// Robust pose by iteratively reweighted Levenberg-Marquardt on SE(3).
//
// The solver sums what each feature kind supplies (pose_terms.h: residuals and a block of the
// normal equations per kind) into one 6x6 system; no Jacobian matrix is stored, which keeps it
// allocation-free. Around that: graduated non-convexity of the Tukey kernel, rounds of rejecting
// whole outlier features, then the degeneracy test, the covariance and the per-feature residuals.
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
#include "pose_terms.h"

namespace epichead::vision {
namespace {

using detail::NormalEquations;
using detail::PoseTerms;
using detail::Rejected;
using detail::Tukey;
using geometry::Matrix6d;
using geometry::Vector6d;

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

// Counts the usable features and their residual dimensions; false (and the status) if too few.
bool enough_features(const PoseProblem& problem, PoseResult& out) {
  int features = 0, dims = 0;
  for (const auto& l : problem.lines) if (l.edgels_px.size() >= 2) { ++features; dims += 2; }
  features += static_cast<int>(problem.points.size());
  dims += 2 * static_cast<int>(problem.points.size());
  for (const auto& e : problem.ellipses) if (e.points_px.size() >= 5) { ++features; dims += 5; }
  features += static_cast<int>(problem.points_3d.size());
  dims += 3 * static_cast<int>(problem.points_3d.size());
  if (features >= 3 && dims >= 6) return true;
  out.status = PoseStatus::TooFewFeatures;
  out.reason = std::to_string(features) + " usable features (need 3 or more)";
  return false;
}

// Undistorts every edgel and ellipse point once (lines, then ellipses; each list's start in
// offsets): the residuals are visited several times per iteration, and undistortion is iterative.
void undistort(const PoseProblem& problem, const Camera& camera, std::vector<Eigen::Vector2d>& normalized,
               std::vector<std::size_t>& offsets) {
  normalized.clear();
  offsets.clear();
  for (const auto& obs : problem.lines) {
    offsets.push_back(normalized.size());
    for (const auto& q : obs.edgels_px) normalized.push_back(camera.pixel_to_normalized(q));
  }
  for (const auto& obs : problem.ellipses) {
    offsets.push_back(normalized.size());
    for (const auto& q : obs.points_px) normalized.push_back(camera.pixel_to_normalized(q));
  }
}

// Robust scale from the median absolute residual at the pose, floored at min_scale.
double robust_scale(const PoseTerms& terms, const Eigen::Isometry3d& pose, double min_scale, std::vector<double>& scratch) {
  scratch.clear();
  terms.residuals(pose, Rejected::Skip, [&](double r, int) { scratch.push_back(std::abs(r)); });
  return std::max(min_scale, 1.4826 * median_in_place(scratch));
}

// Per-feature normalised RMS (rms) and residual count (n) at the pose, rejected features too.
void feature_rms(const PoseTerms& terms, const Eigen::Isometry3d& pose, std::vector<double>& rms, std::vector<double>& n) {
  std::fill(rms.begin(), rms.end(), 0.0);
  std::fill(n.begin(), n.end(), 0.0);
  terms.residuals(pose, Rejected::Include, [&](double r, int slot) { rms[slot] += r * r; n[slot] += 1; });
  for (std::size_t i = 0; i < rms.size(); ++i) rms[i] = n[i] > 0 ? std::sqrt(rms[i] / n[i]) : 0;
}

// One round of Levenberg-Marquardt at a kernel width c that shrinks each iteration toward
// c_floor (graduated non-convexity: the width starts at what the prior's residuals need and
// ends at what the features' sigmas call for; taking the MAD at every iteration instead lets a
// pose biased by many outliers inflate its own scale and stay there). A step is taken only if it
// keeps the features in front and lowers Tukey's cost at this iteration's width. False when the
// normal equations are not finite.
bool levenberg_marquardt(const PoseTerms& terms, const PoseProblem& problem, const PoseOptions& options, double c_floor,
                         double& c, Eigen::Isometry3d& pose, int& iterations) {
  double lambda = 1e-3;
  NormalEquations ne;
  for (int it = 0; it < options.max_iterations; ++it) {
    iterations += 1;
    const Tukey kernel(c);
    terms.normal_equations(pose, kernel, ne);
    if (!ne.H.allFinite() || !ne.g.allFinite()) return false;
    auto cost_at = [&](const Eigen::Isometry3d& p) { return terms.cost(p, kernel); };
    bool improved = false;
    Vector6d step = Vector6d::Zero();
    const StepBasis basis = step_basis(problem, pose);
    for (int tries = 0; tries < 8; ++tries) {
      step = damped_step(basis, ne.H, ne.g, lambda);
      if (!step.allFinite()) break;
      const Eigen::Isometry3d candidate = geometry::apply_left(step, pose);
      if (terms.all_in_front(candidate) && cost_at(candidate) <= ne.cost) {
        pose = candidate;
        lambda = std::max(1e-7, lambda / 10);
        improved = true;
        break;
      }
      lambda *= 10;
    }
    const bool at_floor = c <= c_floor;
    c = std::max(c_floor, c / 1.5);
    if (at_floor && (!improved || step.norm() < options.convergence_step)) break;
  }
  return true;
}

// Rejects the outliers among the worst: every feature beyond outlier_sigma scales whose RMS is
// at least half the worst one's, keeping three. Not all beyond the threshold at once, since one
// gross outlier can make good features look bad until it is gone; not strictly one at a time
// either, since several wrong candidates in one frame would each cost a full re-solve. Returns
// how many were rejected.
int reject_outliers(const PoseOptions& options, double scale, const std::vector<double>& rms,
                    const std::vector<double>& n, std::vector<unsigned char>& rejected) {
  double worst_rms = options.outlier_sigma * scale;
  int remaining = 0;
  for (std::size_t i = 0; i < rms.size(); ++i) {
    if (rejected[i] || n[i] == 0) continue;
    ++remaining;
    worst_rms = std::max(worst_rms, rms[i]);
  }
  const double cut = std::max(options.outlier_sigma * scale, 0.5 * worst_rms);
  int rejected_now = 0;
  for (std::size_t i = 0; i < rms.size() && remaining - rejected_now > 3; ++i) {
    if (rejected[i] || n[i] == 0 || !(rms[i] > cut)) continue;
    rejected[i] = 1;
    ++rejected_now;
  }
  return rejected_now;
}

// Degeneracy and covariance from the final normal equations, within the directions the
// features are asked to fix: with a free turn, H restricted to its complement, and the turn's
// own variance added along its twist.
void degeneracy_and_covariance(const PoseProblem& problem, const PoseOptions& options, const NormalEquations& ne,
                               PoseResult& out) {
  const Matrix6d& H = ne.H;
  const StepBasis basis = step_basis(problem, out.cam_T_obj);
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
  if (!(min_ev > 0) || max_ev / min_ev > options.max_condition) {
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
  const double floor2 = options.min_noise_sigma * options.min_noise_sigma;
  const double sigma2 = std::max(floor2, ne.wsum > basis.dims ? ne.wr2 / (ne.wsum - basis.dims) : 1.0);
  if (out.status != PoseStatus::Ok) {
    out.covariance = Matrix6d::Identity() * 1e6;
    return;
  }
  // H^-1 within the directions the features fix.
  Matrix6d H_inv;
  if (basis.dims == 6) {
    H_inv = H.inverse();
  } else {
    const Eigen::Matrix<double, 6, 5> B = basis.B.leftCols<5>();
    H_inv = B * H_fixed.topLeftCorner<5, 5>().inverse() * B.transpose();
  }
  // Independent edgel noise, plus what each line's edgels share (ne.shared).
  out.covariance = sigma2 * H_inv + H_inv * ne.shared * H_inv;
  if (basis.dims < 6) {
    const double s = problem.free_turn_sigma_rad;
    out.covariance += (s * s) * basis.turn * basis.turn.transpose();
  }
}

// Per-feature RMS (pixels for image features, metres for 3D points) and inlier flags, in slot order.
void feature_residuals(const PoseProblem& problem, const PoseOptions& options, const std::vector<double>& rms,
                       const std::vector<double>& n, const std::vector<unsigned char>& rejected, PoseResult& out) {
  out.residuals.resize(rms.size());
  std::size_t slot = 0;
  auto finish = [&](int feature, double sigma) {
    FeatureResidual& fr = out.residuals[slot];
    fr.feature = feature;
    fr.inlier = n[slot] > 0 && !rejected[slot] && rms[slot] <= options.outlier_sigma * out.scale_px;
    fr.rms = rms[slot] * sigma;
    (fr.inlier ? out.inliers : out.outliers) += 1;
    ++slot;
  };
  for (const auto& o : problem.lines) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.points) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.ellipses) finish(o.feature, o.sigma_px);
  for (const auto& o : problem.points_3d) finish(o.feature, o.sigma_m);
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
  if (!enough_features(problem, out)) return;
  const double focal = 0.5 * (camera_.intrinsics().fx_px + camera_.intrinsics().fy_px);
  undistort(problem, camera_, normalized_, offsets_);
  const std::size_t slots = problem.lines.size() + problem.points.size() + problem.ellipses.size() + problem.points_3d.size();
  rejected_.assign(slots, 0);
  feature_sq_.assign(slots, 0.0);
  feature_n_.assign(slots, 0.0);
  const PoseTerms terms(problem, camera_, focal, normalized_, offsets_, rejected_);

  // Rounds of IRLS; after each, whole features whose RMS residual is far beyond the robust
  // scale are rejected (a wrong candidate line moves all its edgels together, which a
  // per-residual kernel alone can average into a wrong compromise), and the pose is re-solved.
  Eigen::Isometry3d pose = prior;
  const double c_floor = options_.tukey_c * options_.min_scale_px;
  double c = std::max(c_floor, options_.tukey_c * robust_scale(terms, pose, options_.min_scale_px, residual_scratch_));
  for (int round = 0; round < options_.max_rejection_rounds; ++round) {
    if (!levenberg_marquardt(terms, problem, options_, c_floor, c, pose, out.iterations)) {
      out.status = PoseStatus::Diverged;
      out.reason = "non-finite residuals or Jacobian";
      out.cam_T_obj = prior;
      return;
    }
    const double scale = robust_scale(terms, pose, options_.min_scale_px, residual_scratch_);
    feature_rms(terms, pose, feature_sq_, feature_n_);
    if (reject_outliers(options_, scale, feature_sq_, feature_n_, rejected_) == 0) break;
  }

  // Final weights, degeneracy check, covariance and per-feature residuals at the solution.
  out.cam_T_obj = pose;
  out.scale_px = robust_scale(terms, pose, options_.min_scale_px, residual_scratch_);
  NormalEquations ne;
  terms.normal_equations(pose, Tukey(options_.tukey_c * out.scale_px), ne, std::max(0.0, options_.line_shared_sigma_px));
  degeneracy_and_covariance(problem, options_, ne, out);
  feature_rms(terms, pose, feature_sq_, feature_n_);
  feature_residuals(problem, options_, feature_sq_, feature_n_, rejected_, out);
}

}  // namespace epichead::vision
