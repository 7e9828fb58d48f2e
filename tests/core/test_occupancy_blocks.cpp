// The block path of occupancy (core/src/occupancy.cpp): frames whose whole
// evidence is decided once per block of points must give bitwise the answer
// of asking every frame of the map for every point (the reference below
// loops over all frames, with no frame index and no blocks). The map has 8
// frames of the plane scene from poses moved and turned, so their planes
// cross and each point sees several surfaces at several distances: free far
// in front of some, in the band of others, behind others. The block path
// asks frames through a vector kernel compiled per instruction set
// (occupancy_kernel.hpp); the test runs under SOGMM_ISA=sse2, avx2 and the
// default (AVX-512 where the CPU has it), and its bound (no bit differs)
// holds on each because every lane computes the scalar operations in the
// scalar order with no fused multiply-add. Mutation: one ulp added to the
// kernel's surface distance (s * (1 + 1e-15)) makes points differ. The
// lattice's 175,500 points leave 12 in the last block, so the AVX-512
// kernel's packing of in-band lanes (eight at a time, masked past the
// block's end) runs on a partial group too; mutation: its packed lane
// index without the group's offset j makes points differ. A block whose box
// lies in one cell of the frame index reads one list for all its points
// (FrameIndex::one_cell); mutation: one_cell true for every box makes 59
// points differ. The AVX-512 kernel reads the Phi table's four
// coefficients of a lane with one load and a transpose (default kernel);
// mutation: coefficient 2 taken from the transpose's low half makes 7312
// points differ.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "frame_index.hpp"
#include "occupancy_evidence.hpp"
#include "plane_scene.hpp"
#include "sogmm/map.hpp"
#include "sogmm/occupancy.hpp"

namespace {

using sogmm::OccupancyState;
constexpr int kFrames = 8;

// Camera-to-world pose: turned by `yaw` about y, then moved by t.
sogmm::Pose turned(double yaw, double tx, double ty, double tz) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  return {c, 0, s, tx, 0, 1, 0, ty, -s, 0, c, tz, 0, 0, 0, 1};
}

// Built once for both tests (the fits are most of their time).
const sogmm::Map& many_frame_map() {
  static const sogmm::Map map = [] {
    sogmm::MapOptions o;
    o.novelty = false;
    sogmm::Map map(o);
    const sogmm::Camera& cam = sogmm_test::kPlaneCamera;
    std::vector<std::uint16_t> depth(static_cast<std::size_t>(cam.width * cam.height),
                                     static_cast<std::uint16_t>(sogmm_test::kPlaneZ * 1000));
    std::vector<float> gray(depth.size(), 0.5f);
    for (int k = 0; k < kFrames; ++k)
      map.insert_rgbd({depth.data(), gray.data(), cam},
                      turned(0.06 * (k % 5 - 2), 0.15 * (k % 4) - 0.2, 0.1 * (k % 3) - 0.1, -0.07 * k));
    map.flush();
    return map;
  }();
  return map;
}

// Every frame for every point, in frame order (the model of spec/api.md).
void every_frame(const sogmm::Map& map, const std::vector<float>& xyz, std::vector<double>& p,
                 std::vector<std::uint8_t>& s) {
  const sogmm::CameraInfo& info = map.model().camera;
  std::vector<sogmm::Pose> poses;
  for (const sogmm::FrameStats& f : map.frames()) poses.push_back(f.pose);
  const sogmm::detail::FrameIndex index(poses, sogmm::decimated(info.camera, info.decimation), info.depth_min,
                                        info.depth_max);
  const sogmm::OccupancyOptions o;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double x[3] = {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]};
    sogmm::detail::Evidence ev;
    for (std::uint32_t f = 0; f < poses.size(); ++f) {
      const sogmm::detail::Projection pr = index.project(f, x);
      if (pr.pixel < 0) continue;
      const float d = (*map.frame_depth(f))[static_cast<std::size_t>(pr.pixel)];
      if (!std::isnan(d)) ev.add(pr.depth * pr.ray, d * pr.ray, o);
    }
    ev.finish(p[i], &s[i]);
  }
}

TEST(OccupancyBlocks, BitwiseTheAnswerOfEveryFrame) {
  const sogmm::Map& map = many_frame_map();
  ASSERT_EQ(map.frames().size(), static_cast<std::size_t>(kFrames));
  // A lattice through the views (4 cm in x, y; 2.5 cm in z, so many points
  // fall in the band of some surface), behind the planes, beside and behind
  // the cameras.
  std::vector<float> xyz;
  for (int k = 0; k < 130; ++k)
    for (int j = 0; j < 30; ++j)
      for (int i = 0; i < 45; ++i)
        xyz.insert(xyz.end(), {static_cast<float>(-1.6 + 0.08 * i), static_cast<float>(-1.2 + 0.08 * j),
                               static_cast<float>(-0.8 + 0.025 * k)});
  const std::size_t n = xyz.size() / 3;
  std::vector<double> want(n);
  std::vector<std::uint8_t> want_state(n);
  every_frame(map, xyz, want, want_state);
  std::size_t counts[3] = {0, 0, 0}, between = 0;
  for (std::size_t i = 0; i < n; ++i) {
    ++counts[want_state[i]];
    between += want[i] > 1e-9 && want[i] < 1 - 1e-9 && want[i] != 0.5;
  }
  // The lattice holds every state and many fractional answers.
  EXPECT_GT(counts[0], n / 10);
  EXPECT_GT(counts[1], 1000u);
  EXPECT_GT(counts[2], n / 10);
  EXPECT_GT(between, 2000u);
  for (int threads : {1, 2}) {
    std::vector<double> p(n, -1.0);
    std::vector<std::uint8_t> s(n, 255);
    sogmm::occupancy(map, xyz.data(), n, p.data(), s.data(), {}, threads);
    std::size_t differ = 0;
    for (std::size_t i = 0; i < n; ++i) differ += p[i] != want[i] || s[i] != want_state[i];
    EXPECT_EQ(differ, 0u) << threads << " threads";
  }
}

// Phi of the evidence (occupancy_phi.hpp's table between the 9-sigma cuts)
// against 0.5 erfc(-x / sqrt 2) on a grid finer than the table's nodes
// (1/64) by a factor 2^11 and offset from them, past the cuts on both sides.
TEST(OccupancyPhi, WithinItsStatedBoundOfErfc) {
  double worst = 0.0, at = 0.0;
  for (long k = -1572864; k <= 1572864; ++k) {  // x in [-12, 12] by 2^-17, plus a third of a step
    const double x = (static_cast<double>(k) + 1.0 / 3.0) / 131072.0;
    const double err = std::abs(sogmm::detail::Evidence::phi(x) - 0.5 * std::erfc(-x / std::sqrt(2.0)));
    if (err > worst) worst = err, at = x;
  }
  EXPECT_LE(worst, sogmm::detail::kPhiTableError) << "at x = " << at;
  // The cuts and the ends of the table.
  for (double x : {-9.0, 9.0, -8.999999, 8.999999, -9.000001, 9.000001, 0.0})
    EXPECT_LE(std::abs(sogmm::detail::Evidence::phi(x) - 0.5 * std::erfc(-x / std::sqrt(2.0))),
              sogmm::detail::kPhiTableError)
        << x;
}

TEST(OccupancyBlocks, BehindEverySurfaceAndOutsideEveryViewIsUnknown) {
  const sogmm::Map& map = many_frame_map();
  // Far behind every plane (the nearest frame's is at z = 2 - 0.07 * 13 plus its
  // turn), behind every camera, and far beside every view: in blocks of their own.
  std::vector<float> xyz;
  for (int i = 0; i < 200; ++i) {
    const float a = static_cast<float>(i % 10) * 0.02f, b = static_cast<float>(i / 10) * 0.02f;
    xyz.insert(xyz.end(), {a - 0.1f, b - 0.2f, 3.0f});   // behind the planes, inside the views
    xyz.insert(xyz.end(), {a, b, -2.0f});                // behind the cameras
    xyz.insert(xyz.end(), {40.0f + a, b, 2.0f + b});     // beside every view
  }
  const std::size_t n = xyz.size() / 3;
  std::vector<double> p(n, -1.0);
  std::vector<std::uint8_t> s(n, 255);
  sogmm::occupancy(map, xyz.data(), n, p.data(), s.data());
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(p[i], 0.5) << i;
    EXPECT_EQ(s[i], static_cast<int>(OccupancyState::Unknown)) << i;
  }
}

}  // namespace
