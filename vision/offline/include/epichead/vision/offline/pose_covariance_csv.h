#pragma once
// The covariance of each tracked pose, beside poses.csv (`epichead track` writes
// vision_covariance.csv): frame,t_s, then the 21 entries of the upper triangle of the 6x6
// covariance in the order of geometry/pose_covariance.h — the left perturbation of cam_T_obj,
// translation (m) then rotation (rad), in the camera frame — row by row:
// c_tx_tx,c_tx_ty,...,c_tx_rz,c_ty_ty,...,c_rz_rz (m^2, m*rad, rad^2).
#include <expected>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace epichead::vision {

struct StampedCovariance {
  int frame = 0;
  double t_s = 0;
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Identity();
};

// The header's column names, in file order.
const std::vector<std::string>& pose_covariance_columns();

// Reads the file; a malformed row, a non-finite entry, frames not increasing or a matrix that is
// not positive semi-definite give "file:line: what".
std::expected<std::vector<StampedCovariance>, std::string> read_pose_covariance_csv(const std::string& path);
std::expected<void, std::string> write_pose_covariance_csv(const std::string& path,
                                                           const std::vector<StampedCovariance>& rows);

}  // namespace epichead::vision
