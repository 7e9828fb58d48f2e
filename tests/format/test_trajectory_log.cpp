// The library's Redwood .log reader and writer (sogmm/trajectory_log.hpp).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "sogmm/error.hpp"
#include "sogmm/trajectory_log.hpp"

namespace {

using sogmm::format::parse_trajectory_log;
using Pose = std::array<double, 16>;

// Rotation about z by `a` and about x by `b`, then a translation: rigid by construction.
Pose pose(double a, double b, double tx, double ty, double tz) {
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
  return {ca, -sa * cb, sa * sb, tx, sa, ca * cb, -ca * sb, ty, 0, sb, cb, tz, 0, 0, 0, 1};
}

std::string message_of(const std::string& text) {
  try {
    parse_trajectory_log(text, "t.log");
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidData);
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << text;
  return "";
}

TEST(TrajectoryLog, WrittenPosesReadBackBitwiseWithTheirBlockIds) {
  const std::vector<Pose> poses = {pose(0.1, 0.2, 1.0 / 3, -2.5, 1e-7), pose(-1.3, 0.7, 4, 5, 6),
                                   pose(3.0, -0.01, 0, 0, 0)};
  const std::string text = sogmm::format::format_trajectory_log(poses);
  EXPECT_EQ(text.substr(0, 6), "0 1 3\n");
  const auto t = parse_trajectory_log(text, "t.log");
  ASSERT_EQ(t.poses.size(), 3u);
  EXPECT_EQ(t.ids, (std::vector<long long>{0, 1, 2}));
  for (std::size_t k = 0; k < 3; ++k)
    for (int i = 0; i < 16; ++i) EXPECT_EQ(t.poses[k][i], poses[k][i]);
}

TEST(TrajectoryLog, IdsAreTheHeadersFirstNumbersAndBlankLinesAreSkipped) {
  const auto t = parse_trajectory_log(
      "\n7 7 2\r\n1 0 0 0.5\n0 1 0 0\n\n0 0 1 0\n0 0 0 1\n12\t12\t2\n1 0 0 0\n0 1 0 0\n0 0 1 -1\n0 0 0 1\n", "t.log");
  EXPECT_EQ(t.ids, (std::vector<long long>{7, 12}));
  EXPECT_EQ(t.poses[0][3], 0.5);
  EXPECT_EQ(t.poses[1][11], -1.0);
}

TEST(TrajectoryLog, MalformedFilesNameTheLine) {
  EXPECT_NE(message_of("0 0\n").find("t.log:1: expected a header line"), std::string::npos);
  EXPECT_NE(message_of("0 0 1\n1 0 0 0\n0 1 0 0\n").find("t.log:3: truncated"), std::string::npos);
  EXPECT_NE(message_of("0 0 1\n1 0 0 0\n0 1 0 nan\n0 0 1 0\n0 0 0 1\n").find("t.log:3: expected 4 finite"),
            std::string::npos);
  EXPECT_NE(message_of("0 0 1\n2 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n").find("t.log:5: pose 0 is not a rigid"),
            std::string::npos);
  EXPECT_NE(message_of(" \n\n").find("t.log: no pose"), std::string::npos);
}

TEST(TrajectoryLog, WriteIsAtomicAndReadRefusesAFolder) {
  char dir[] = "/tmp/sogmm_traj_XXXXXX";
  ASSERT_NE(mkdtemp(dir), nullptr);
  const std::string path = std::string(dir) + "/t.log";
  sogmm::format::write_trajectory_log(path, {pose(0.3, 0.1, 1, 2, 3)});
  EXPECT_EQ(sogmm::format::read_trajectory_log(path).poses[0][7], 2.0);
  // A target that is a folder is refused and left alone.
  const std::string sub = std::string(dir) + "/sub";
  ASSERT_EQ(mkdir(sub.c_str(), 0700), 0);
  EXPECT_THROW(sogmm::format::write_trajectory_log(sub, {pose(0, 0, 0, 0, 0)}), sogmm::Error);
  try {
    sogmm::format::read_trajectory_log(sub);
    ADD_FAILURE() << "read a folder";
  } catch (const sogmm::Error& e) {
    EXPECT_EQ(e.code(), sogmm::ErrorCode::Io);
  }
  rmdir(sub.c_str());
  unlink(path.c_str());
  rmdir(dir);
}

}  // namespace
