#include "epichead/vision/offline/stamped_pose.h"

#include <array>
#include <cmath>

#include "csv_rows.h"

namespace epichead::vision {
namespace {

using Error = std::unexpected<std::string>;

const std::vector<std::string_view> kColumns{"frame", "t_s", "tx", "ty", "tz", "qw", "qx", "qy", "qz"};

}  // namespace

Eigen::Isometry3d make_pose(const Eigen::Vector3d& t, const Eigen::Quaterniond& q) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q.normalized().toRotationMatrix();
  pose.translation() = t;
  return pose;
}

std::expected<std::vector<StampedPose>, std::string> read_pose_csv(const std::string& path) {
  auto table = csv::read(path);
  if (!table) return Error(table.error());
  auto with_status = csv::check_header(*table, kColumns, "status");
  if (!with_status) return Error(with_status.error());
  const std::size_t columns = kColumns.size() + (*with_status ? 1 : 0);

  std::vector<StampedPose> poses;
  poses.reserve(table->rows.size());
  for (const csv::Row& row : table->rows) {
    const std::string at = csv::where(*table, row);
    if (row.fields.size() != columns)
      return Error(at + "expected " + std::to_string(columns) + " columns, got " + std::to_string(row.fields.size()));
    StampedPose pose;
    const auto frame = csv::parse_int(row.fields[0]);
    if (!frame) return Error(at + "frame is not a whole number ('" + row.fields[0] + "')");
    if (*frame < 0) return Error(at + "frame must not be negative, got " + row.fields[0]);
    if (!poses.empty() && *frame == poses.back().frame) return Error(at + "duplicate frame " + std::to_string(*frame));
    if (!poses.empty() && *frame < poses.back().frame)
      return Error(at + "frame " + std::to_string(*frame) + " after frame " + std::to_string(poses.back().frame) +
                   " (frames must increase)");
    pose.frame = *frame;
    std::array<double, 8> v{};  // t_s, tx, ty, tz, qw, qx, qy, qz
    for (std::size_t i = 0; i < v.size(); ++i) {
      const auto value = csv::parse_finite(row.fields[i + 1]);
      if (!value) return Error(at + csv::number_problem(kColumns[i + 1], row.fields[i + 1]));
      v[i] = *value;
    }
    pose.t_s = v[0];
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    // A quaternion this small carries no rotation: normalising it would amplify noise.
    if (!(q.norm() > 1e-6)) return Error(at + "zero quaternion (qw,qx,qy,qz all ~0)");
    pose.cam_T_obj = make_pose(Eigen::Vector3d(v[1], v[2], v[3]), q);
    if (*with_status) pose.status = row.fields.back();
    poses.push_back(std::move(pose));
  }
  return poses;
}

std::expected<void, std::string> write_pose_csv(const std::string& path, const std::vector<StampedPose>& poses) {
  bool with_status = false;
  for (const auto& p : poses) {
    if (!p.status.empty()) with_status = true;
    if (p.status.find_first_of(",\r\n") != std::string::npos)
      return Error(path + ": status of frame " + std::to_string(p.frame) + " contains a comma or line break");
  }
  std::string text = "frame,t_s,tx,ty,tz,qw,qx,qy,qz";
  text += with_status ? ",status\n" : "\n";
  for (const auto& p : poses) {
    Eigen::Quaterniond q(p.cam_T_obj.linear());
    q.normalize();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // one of the two signs, so files compare equal
    text += std::to_string(p.frame);
    text += ',';
    csv::append_exact(text, p.t_s);  // times need every digit (absolute clocks, fine steps)
    for (double v : {p.cam_T_obj.translation().x(), p.cam_T_obj.translation().y(), p.cam_T_obj.translation().z(),
                     q.w(), q.x(), q.y(), q.z()}) {
      text += ',';
      csv::append_9g(text, v);
    }
    if (with_status) {
      text += ',';
      text += p.status;
    }
    text += '\n';
  }
  return csv::write_file(path, text);
}

}  // namespace epichead::vision
