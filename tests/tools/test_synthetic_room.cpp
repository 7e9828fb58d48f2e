// The synthetic room loop of `sogmm demo --write-frame --loop` (issue 18):
// the trajectory closes exactly and the ray-cast depth equals the surfaces'
// closed forms at hand-computed pixels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <unistd.h>

#include "sequence.hpp"
#include "sogmm/model.hpp"
#include "synthetic_room.hpp"

namespace {

using sogmm::tools::Pose;

Pose multiply(const Pose& a, const Pose& b) {
  Pose c{};
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j) c[4 * r + j] += a[4 * r + k] * b[4 * k + j];
  return c;
}

double max_abs_diff(const Pose& a, const Pose& b) {
  double m = 0;
  for (int i = 0; i < 16; ++i) m = std::max(m, std::abs(a[i] - b[i]));
  return m;
}

int depth_at(const sogmm::tools::LoadedFrame& f, int u, int v) { return f.depth[static_cast<std::size_t>(v) * f.width + u]; }

const double kCos = std::cos(15.0 * M_PI / 180.0), kSin = std::sin(15.0 * M_PI / 180.0);

TEST(SyntheticRoom, LoopClosesWithEqualSteps) {
  const int n = 300;
  std::vector<Pose> poses;
  for (int k = 0; k < n; ++k) poses.push_back(sogmm::tools::room_loop_pose(k, n));
  EXPECT_LT(max_abs_diff(poses.front(), poses.back()), 1e-12) << "the last frame does not return to the start";
  // Every step is the same motion: a turn of 2 pi / (n - 1) about the
  // vertical through the orbit centre, so the relative poses are all equal.
  const Pose step0 = multiply(sogmm::tools::inverse_rigid(poses[0]), poses[1]);
  const double angle = std::acos((step0[0] + step0[5] + step0[10] - 1.0) / 2.0);
  EXPECT_NEAR(angle, 2.0 * M_PI / (n - 1), 1e-9);
  // Chord between consecutive centres of a circle of radius 0.5.
  const double chord = std::hypot(poses[1][3] - poses[0][3], poses[1][11] - poses[0][11]);
  EXPECT_NEAR(chord, 2 * 0.5 * std::sin(M_PI / (n - 1)), 1e-12);
  for (int k = 0; k + 1 < n; ++k) {
    EXPECT_EQ(sogmm::rigid_pose_error(poses[k]), "") << "pose " << k;
    const Pose step = multiply(sogmm::tools::inverse_rigid(poses[k]), poses[k + 1]);
    ASSERT_LT(max_abs_diff(step, step0), 1e-12) << "step " << k;
  }
  // The trajectory file reads back bit for bit (%.17g).
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("sogmm_room_loop_" + std::to_string(::getpid()) + ".log"))
                               .string();
  sogmm::tools::write_trajectory_log(path, poses);
  const std::vector<Pose> back = sogmm::tools::read_trajectory(path);
  std::filesystem::remove(path);
  ASSERT_EQ(back.size(), poses.size());
  for (int k = 0; k < n; ++k) EXPECT_EQ(back[k], poses[k]) << "pose " << k;
}

// Frame 0: camera at (0, 0, 0.5) looking along +z, 15 degrees down. Pixel
// (320, 240) has world direction (d, cos15 d + sin15, cos15 - sin15 d) with
// d = 0.5 / 525 and meets the wall z = 2 at depth 1.5 / (cos15 - sin15 d).
TEST(SyntheticRoom, FrameZeroWallAndFloor) {
  const auto f = sogmm::tools::room_frame_at(sogmm::tools::room_loop_pose(0, 300));
  ASSERT_EQ(f.width, 640);
  ASSERT_EQ(f.height, 480);
  const double d = 0.5 / 525;
  EXPECT_EQ(depth_at(f, 320, 240), 1553);  // 1553.31 mm by hand
  EXPECT_EQ(depth_at(f, 320, 240), std::lround(1500.0 / (kCos - kSin * d)));
  // Pixel (320, 479): direction y = cos15 * 239.5 / 525 + sin15; the floor
  // y = 1 is at depth 1 / y = 1429.66 mm (hit at z = 1.71 < 2: before the wall).
  EXPECT_EQ(depth_at(f, 320, 479), 1430);
  EXPECT_EQ(depth_at(f, 320, 479), std::lround(1000.0 / (kCos * 239.5 / 525 + kSin)));
  // Every pixel sees a surface of the closed room within 3 m.
  for (std::uint16_t z : f.depth) ASSERT_TRUE(z > 0 && z <= 3000);
}

// Frame 1 of 5 (a quarter turn): camera at (0.5, 0, 0) looking along +x. The
// ray of pixel (320, 240) has y component cos15 d + sin15 (d = 0.5 / 525) and
// reaches y = 0.3, the top of the box [1.2, 1.8] x [0.3, 1] x [-0.7, 0.1], at
// x = 1.617, z = -0.0005: depth 0.3 / (cos15 d + sin15) = 1155.01 mm.
TEST(SyntheticRoom, QuarterTurnSeesBoxTop) {
  const auto f = sogmm::tools::room_frame_at(sogmm::tools::room_loop_pose(1, 5));
  EXPECT_EQ(depth_at(f, 320, 240), 1155);
  EXPECT_EQ(depth_at(f, 320, 240), std::lround(300.0 / (kCos * 0.5 / 525 + kSin)));
}

// Frame 1 of 13 (30 degrees): the sphere centred (0.8, 0.7, 1.4) with radius
// 0.3 projects near pixel (316, 402); in camera coordinates its centre is
// (-0.00718, 0.38823, 1.25570) and the ray (u - cx, v - cy, 525) / 525 meets
// it at depth 968.99 mm (the smaller root of |t d - c|^2 = r^2).
TEST(SyntheticRoom, SphereDepth) {
  const auto f = sogmm::tools::room_frame_at(sogmm::tools::room_loop_pose(1, 13));
  EXPECT_EQ(depth_at(f, 316, 402), 969);
}

}  // namespace
