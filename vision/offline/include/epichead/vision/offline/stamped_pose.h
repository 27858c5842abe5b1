#pragma once
// A pose cam_T_obj at a frame and time, and the CSV files that hold them
// (init.csv, gt.csv, poses.csv: frame,t_s,tx,ty,tz,qw,qx,qy,qz[,status]).
#include <expected>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace epichead::vision {

struct StampedPose {
  int frame = 0;
  double t_s = 0;
  Eigen::Isometry3d cam_T_obj = Eigen::Isometry3d::Identity();
  std::string status;  // poses.csv only (tracked, degraded, predicted, lost); empty elsewhere
};

// Reads a pose CSV. The header must name the columns above (status optional). A malformed
// row gives "file:line: what". Quaternions are normalised; a zero quaternion is an error.
std::expected<std::vector<StampedPose>, std::string> read_pose_csv(const std::string& path);
// Writes a pose CSV; the status column is written when any pose has a status.
std::expected<void, std::string> write_pose_csv(const std::string& path, const std::vector<StampedPose>& poses);

Eigen::Isometry3d make_pose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q);

}  // namespace epichead::vision
