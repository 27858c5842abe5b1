// Pose CSVs (init.csv, gt.csv, poses.csv): tolerant reading, file:line errors, exact round trips.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "epichead/vision/offline/stamped_pose.h"
#include "common/readme_columns.h"
#include "common/temp_dir.h"

using epichead::vision::make_pose;
using epichead::vision::read_pose_csv;
using epichead::vision::StampedPose;
using epichead::vision::write_pose_csv;

namespace {

namespace fs = std::filesystem;

struct TempDir : epichead::testing::TempDir {
  TempDir() : epichead::testing::TempDir("epichead_test_stamped_pose") {}
};

const std::string kHeader = "frame,t_s,tx,ty,tz,qw,qx,qy,qz\n";

std::string read_error(const TempDir& dir, const std::string& text) {
  auto poses = read_pose_csv(dir.write("poses.csv", text));
  REQUIRE_FALSE(poses.has_value());
  return poses.error();
}

}  // namespace

TEST_CASE("a pose CSV reads frames, times, translations and normalised quaternions") {
  TempDir dir;
  auto poses = read_pose_csv(dir.write("gt.csv", kHeader + "0,0,0.1,0.2,0.5,2,0,0,0\n3,0.12,-1,0,2,0,0,0,1\n"));
  REQUIRE(poses.has_value());
  REQUIRE(poses->size() == 2);
  CHECK((*poses)[0].frame == 0);
  CHECK((*poses)[0].cam_T_obj.translation().isApprox(Eigen::Vector3d(0.1, 0.2, 0.5)));
  CHECK((*poses)[0].cam_T_obj.linear().isApprox(Eigen::Matrix3d::Identity()));  // (2,0,0,0) normalised
  CHECK((*poses)[1].frame == 3);
  CHECK((*poses)[1].t_s == 0.12);
  // (0,0,0,1): half a turn about z.
  CHECK((*poses)[1].cam_T_obj.linear().isApprox(Eigen::Vector3d(-1, -1, 1).asDiagonal().toDenseMatrix()));
  CHECK((*poses)[1].status.empty());
}

TEST_CASE("a pose CSV tolerates CRLF, blank lines, spaces and a trailing status column") {
  TempDir dir;
  const std::string text = "\r\n frame , t_s,tx,ty,tz,qw,qx,qy,qz , status\r\n"
                           "\r\n"
                           " 1 , 0.04 , 0 , 0 , 1 , 1 , 0 , 0 , 0 , tracked \r\n"
                           "   \r\n"
                           "2,0.08,0,0,1,1,0,0,0,lost\r\n";
  auto poses = read_pose_csv(dir.write("poses.csv", text));
  REQUIRE(poses.has_value());
  REQUIRE(poses->size() == 2);
  CHECK((*poses)[0].status == "tracked");
  CHECK((*poses)[1].status == "lost");
  CHECK((*poses)[1].t_s == 0.08);
}

TEST_CASE("the real init.csv reads as one pose") {
  auto poses = read_pose_csv(std::string(EPICHEAD_SHARED_DATA) + "/teabox/init.csv");
  REQUIRE(poses.has_value());
  REQUIRE(poses->size() == 1);
  CHECK((*poses)[0].cam_T_obj.translation().z() == Approx(0.448947131));
}

TEST_CASE("malformed pose rows are reported as file:line with what is wrong") {
  TempDir dir;
  const std::string file = (dir.path / "poses.csv").string();
  CHECK(read_error(dir, kHeader + "0,0,0,0,1,1,0,0\n") == file + ":2: expected 9 columns, got 8");
  CHECK(read_error(dir, kHeader + "\n0,0,0,0,1,1,0,0,0,extra\n") == file + ":3: expected 9 columns, got 10");
  CHECK(read_error(dir, kHeader + "0,0,0,0,1,1,0,0,0\n1,0.1,abc,0,1,1,0,0,0\n") == file + ":3: tx is not a number ('abc')");
  CHECK(read_error(dir, kHeader + "0,0,0,0,1,1,0,0,0\n1,0.1,0,0,1,1,0,0,1.5x\n") == file + ":3: qz is not a number ('1.5x')");
  CHECK(read_error(dir, kHeader + "0,nan,0,0,1,1,0,0,0\n") == file + ":2: t_s is not finite ('nan')");
  CHECK(read_error(dir, kHeader + "0,0,0,0,inf,1,0,0,0\n") == file + ":2: tz is not finite ('inf')");
  CHECK(read_error(dir, kHeader + "0,0,0,0,1,,0,0,0\n") == file + ":2: qw is empty");
  CHECK(read_error(dir, kHeader + "0,0,0,0,1,0,0,0,0\n") == file + ":2: zero quaternion (qw,qx,qy,qz all ~0)");
  CHECK(read_error(dir, kHeader + "x,0,0,0,1,1,0,0,0\n") == file + ":2: frame is not a whole number ('x')");
  CHECK(read_error(dir, kHeader + "1.5,0,0,0,1,1,0,0,0\n") == file + ":2: frame is not a whole number ('1.5')");
  CHECK(read_error(dir, kHeader + "-1,0,0,0,1,1,0,0,0\n") == file + ":2: frame must not be negative, got -1");
  CHECK(read_error(dir, kHeader + "4,0,0,0,1,1,0,0,0\n4,0.1,0,0,1,1,0,0,0\n") == file + ":3: duplicate frame 4");
  CHECK(read_error(dir, kHeader + "4,0,0,0,1,1,0,0,0\n2,0.1,0,0,1,1,0,0,0\n") ==
        file + ":3: frame 2 after frame 4 (frames must increase)");
}

TEST_CASE("a pose CSV needs its header") {
  TempDir dir;
  const std::string file = (dir.path / "poses.csv").string();
  CHECK(read_error(dir, "") == file + ": empty (no header line)");
  CHECK(read_error(dir, "\n\n  \n") == file + ": empty (no header line)");
  CHECK_THAT(read_error(dir, "0,0,0,0,1,1,0,0,0\n"), Catch::StartsWith(file + ":1: header must be 'frame,t_s,tx,ty,tz,qw,qx,qy,qz'"));
  CHECK_THAT(read_error(dir, "frame,t_s,tx,ty,tz,qx,qy,qz,qw\n"), Catch::StartsWith(file + ":1: header must be"));
  CHECK_THAT(read_error(dir, "frame,t_s,tx,ty,tz,qw,qx,qy,qz,score\n"), Catch::StartsWith(file + ":1: header must be"));
  auto missing = read_pose_csv((dir.path / "absent.csv").string());
  REQUIRE_FALSE(missing.has_value());
  CHECK(missing.error() == (dir.path / "absent.csv").string() + ": cannot open");
}

TEST_CASE("a header-only pose CSV is an empty list") {
  TempDir dir;
  auto poses = read_pose_csv(dir.write("poses.csv", kHeader));
  REQUIRE(poses.has_value());
  CHECK(poses->empty());
}

TEST_CASE("write_pose_csv round-trips poses to 1e-9 and times exactly") {
  TempDir dir;
  std::vector<StampedPose> poses;
  for (int i = 0; i < 20; ++i) {
    StampedPose p;
    p.frame = 3 * i;
    p.t_s = 1436509052.249713 + i / 30.0;  // an absolute clock: every digit matters
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * i - 2.0, Eigen::Vector3d(1, -2, 0.5 + i).normalized()));
    p.cam_T_obj = make_pose(Eigen::Vector3d(0.01 * i - 0.1, 1.0 / 3.0, 12.3456789 + i), q);
    poses.push_back(p);
  }
  const std::string path = (dir.path / "out.csv").string();
  REQUIRE(write_pose_csv(path, poses).has_value());
  std::ifstream in(path);
  std::string header;
  std::getline(in, header);
  CHECK(header == "frame,t_s,tx,ty,tz,qw,qx,qy,qz");  // no status column when no pose has one
  auto back = read_pose_csv(path);
  REQUIRE(back.has_value());
  REQUIRE(back->size() == poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    CHECK((*back)[i].frame == poses[i].frame);
    CHECK((*back)[i].t_s == poses[i].t_s);
    CHECK(((*back)[i].cam_T_obj.translation() - poses[i].cam_T_obj.translation()).norm() < 1e-7);  // 9 digits of ~12 m
    CHECK(((*back)[i].cam_T_obj.linear() - poses[i].cam_T_obj.linear()).norm() < 1e-8);
  }
}

TEST_CASE("write_pose_csv writes the status column when a pose has a status") {
  TempDir dir;
  std::vector<StampedPose> poses(2);
  poses[0].frame = 0;
  poses[1].frame = 1;
  poses[1].status = "lost";
  const std::string path = (dir.path / "poses.csv").string();
  REQUIRE(write_pose_csv(path, poses).has_value());
  auto back = read_pose_csv(path);
  REQUIRE(back.has_value());
  CHECK((*back)[0].status.empty());
  CHECK((*back)[1].status == "lost");
  poses[0].status = "a,b";
  CHECK_FALSE(write_pose_csv(path, poses).has_value());
  CHECK_FALSE(write_pose_csv((dir.path / "no/such/dir.csv").string(), poses).has_value());
}

TEST_CASE("pose CSVs are written as README.md documents them: its columns, cam_T_obj, qw first, unit quaternion, qw >= 0") {
  TempDir dir;
  const std::string path = (dir.path / "poses.csv").string();
  // A turn of 300 deg about x: Eigen's quaternion for it may come out with w < 0.
  const Eigen::Quaterniond q(Eigen::AngleAxisd(300.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()));
  REQUIRE(write_pose_csv(path, {{7, 0.25, make_pose({0.1, -0.2, 0.9}, q), "tracked"}}));
  std::ifstream in(path);
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  const auto documented = epichead::testing::documented_columns(EPICHEAD_SOURCE_DIR "/README.md", "**Pose CSVs**");
  CHECK(header == epichead::testing::joined(documented));
  double v[9];
  char status[16] = {};
  REQUIRE(std::sscanf(row.c_str(), "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf,%15s", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6],
                      &v[7], &v[8], status) == 10);
  CHECK(v[2] == Approx(0.1));  // the object's origin in the camera frame, m
  CHECK(v[4] == Approx(0.9));
  const Eigen::Quaterniond written(v[5], v[6], v[7], v[8]);  // w, x, y, z
  CHECK(written.w() >= 0);
  CHECK(written.norm() == Approx(1.0).epsilon(1e-6));
  CHECK(written.angularDistance(q) < 1e-6);
  CHECK(std::string(status) == "tracked");
}
