// The sequence CSV readers (stamped_pose.h, sequence.h): the first input byte picks the file,
// the rest is its text: 'i' init.csv and 'g' gt.csv (read_pose_csv), 'u' imu.csv
// (read_imu_csv), 'f' frames.csv (read_frames_csv), 'c' vision_covariance.csv
// (read_pose_covariance_csv); any other byte picks by its value modulo 5.
// Properties: rows or a one-line error naming the file, never a crash; what was read, written
// by the matching writer, reads back the same (times and IMU values exactly, poses to the
// writer's 9 significant digits, covariances exactly).
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "epichead/vision/offline/pose_covariance_csv.h"
#include "epichead/vision/offline/sequence.h"
#include "epichead/vision/offline/stamped_pose.h"
#include "fuzz_support.h"

using namespace epichead::vision;
using epichead::fuzz::check;

namespace {

enum class Kind { Init, Gt, Imu, Frames, Covariance };

Kind pick(std::uint8_t b) {
  switch (b) {
    case 'i': return Kind::Init;
    case 'g': return Kind::Gt;
    case 'u': return Kind::Imu;
    case 'f': return Kind::Frames;
    case 'c': return Kind::Covariance;
    default: return static_cast<Kind>(b % 5);
  }
}

template <typename T>
void check_error(const std::expected<T, std::string>& r, const std::string& path) {
  epichead::fuzz::check_one_line(r.error(), "csv reader");
  check(r.error().starts_with(path), "the error does not name the file: " + r.error());
}

bool close(double a, double b) { return std::abs(a - b) <= 1e-8 * std::max(1.0, std::max(std::abs(a), std::abs(b))); }

void poses(const std::string& path) {
  auto a = read_pose_csv(path);
  if (!a) return check_error(a, path);
  for (const auto& p : *a) {
    check(p.cam_T_obj.matrix().allFinite(), "a pose is not finite");
    check(std::abs(Eigen::Quaterniond(p.cam_T_obj.linear()).norm() - 1) < 1e-9, "a rotation is not normalised");
  }
  const std::string again = path + ".written";
  const auto w = write_pose_csv(again, *a);
  check(w.has_value(), "write_pose_csv failed: " + (w ? std::string() : w.error()));
  auto b = read_pose_csv(again);
  check(b.has_value(), "a written pose file does not read back: " + (b ? std::string() : b.error()));
  check(a->size() == b->size(), "pose count changed");
  for (std::size_t i = 0; i < a->size(); ++i) {
    const StampedPose& p = (*a)[i];
    const StampedPose& q = (*b)[i];
    check(p.frame == q.frame && p.t_s == q.t_s && p.status == q.status, "frame, time or status changed");
    for (int k = 0; k < 3; ++k) check(close(p.cam_T_obj.translation()[k], q.cam_T_obj.translation()[k]), "translation changed");
    const Eigen::Quaterniond qa(p.cam_T_obj.linear()), qb(q.cam_T_obj.linear());
    check(std::abs(qa.dot(qb)) > 1 - 1e-12, "rotation changed");
  }
}

void imu(const std::string& path) {
  auto a = read_imu_csv(path);
  if (!a) return check_error(a, path);
  const std::string again = path + ".written";
  const auto w = write_imu_csv(again, *a);
  check(w.has_value(), "write_imu_csv failed: " + (w ? std::string() : w.error()));
  auto b = read_imu_csv(again);
  check(b.has_value(), "a written IMU file does not read back: " + (b ? std::string() : b.error()));
  check(a->size() == b->size(), "sample count changed");
  for (std::size_t i = 0; i < a->size(); ++i) {
    check((*a)[i].t_s == (*b)[i].t_s && (*a)[i].gyro_radps == (*b)[i].gyro_radps &&
              (*a)[i].accel_mps2 == (*b)[i].accel_mps2,
          "an IMU sample changed");
  }
}

void frames(const std::string& path) {
  auto a = read_frames_csv(path);
  if (!a) return check_error(a, path);
  const std::string again = path + ".written";
  const auto w = write_frames_csv(again, *a);
  check(w.has_value(), "write_frames_csv failed: " + (w ? std::string() : w.error()));
  auto b = read_frames_csv(again);
  check(b.has_value(), "a written frames file does not read back: " + (b ? std::string() : b.error()));
  check(a->size() == b->size(), "frame count changed");
  for (std::size_t i = 0; i < a->size(); ++i) {
    check((*a)[i].frame == (*b)[i].frame && (*a)[i].t_s == (*b)[i].t_s && (*a)[i].file == (*b)[i].file,
          "a frame entry changed");
  }
}

void covariances(const std::string& path) {
  auto a = read_pose_covariance_csv(path);
  if (!a) return check_error(a, path);
  const std::string again = path + ".written";
  const auto w = write_pose_covariance_csv(again, *a);
  check(w.has_value(), "write_pose_covariance_csv failed: " + (w ? std::string() : w.error()));
  auto b = read_pose_covariance_csv(again);
  check(b.has_value(), "a written covariance file does not read back: " + (b ? std::string() : b.error()));
  check(a->size() == b->size(), "row count changed");
  for (std::size_t i = 0; i < a->size(); ++i) {
    const auto& p = (*a)[i];
    const auto& q = (*b)[i];
    check(p.frame == q.frame && p.t_s == q.t_s, "frame or time changed");
    for (int r = 0; r < 6; ++r)
      for (int c = 0; c < 6; ++c) check(p.covariance(r, c) == q.covariance(r, c), "a covariance entry changed");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  auto& scratch = epichead::fuzz::Scratch::get();
  scratch.clear();
  const std::string_view text = epichead::fuzz::as_text(data + 1, size - 1);
  switch (pick(data[0])) {
    case Kind::Init: poses(scratch.write("init.csv", text)); break;
    case Kind::Gt: poses(scratch.write("gt.csv", text)); break;
    case Kind::Imu: imu(scratch.write("imu.csv", text)); break;
    case Kind::Frames: frames(scratch.write("frames.csv", text)); break;
    case Kind::Covariance: covariances(scratch.write("vision_covariance.csv", text)); break;
  }
  return 0;
}
