// Which of a frame's points tracking registers (core/src/tracking_overlap.hpp):
// points on hand-placed pixels of earlier cameras, kept or dropped by the
// closed form of the pinhole projection. Double arithmetic on a handful of
// points: no kernel (SSE2, AVX2, AVX-512) takes part, so the verdicts are the
// same on every one.
#include <gtest/gtest.h>

#include <vector>

#include "map_test_util.hpp"
#include "tracking_overlap.hpp"

namespace {

using namespace sogmm_test;
namespace d = sogmm::detail;

// 200 x 150 pixels, f = 150, principal point (99.5, 74.5): pixels 0 to 199
// across, 0 to 149 down; at depth 2 m a pixel is 2 / 150 m.
const sogmm::Camera kCamera{200, 150, 150, 150, 99.5, 74.5};
constexpr double kMargin = 8;

sogmm::PointsView view_of(const std::vector<float>& p) { return {p.data(), p.size() / 4, false}; }

// The world point at pixel (u, v) and depth 2 of the camera at x = cam_x
// (looking along +z), with the row's gray as a tag.
void add(std::vector<float>& p, double cam_x, double u, double v, float tag) {
  const double z = 2.0;
  p.insert(p.end(), {float(cam_x + (u - kCamera.cx) * z / kCamera.fx), float((v - kCamera.cy) * z / kCamera.fy),
                     float(z), tag});
}

std::vector<float> tags(const std::vector<float>& p) {
  std::vector<float> t;
  for (std::size_t i = 3; i < p.size(); i += 4) t.push_back(p[i]);
  return t;
}

TEST(TrackingOverlap, KeepsThePointsAnEarlierFrameSawInsideItsMargin) {
  // Frame points placed (identity pose) at pixels of the earlier camera at
  // x = 0.5 m: inside the margin on each side (kept), just outside (dropped).
  std::vector<float> p;
  const double lo = kMargin, hi_u = 199 - kMargin, hi_v = 149 - kMargin;
  add(p, 0.5, lo + 0.01, 70, 1);   // kept: 0.01 pixel inside the left margin
  add(p, 0.5, lo - 0.01, 70, 2);   // dropped
  add(p, 0.5, hi_u - 0.01, 70, 3); // kept
  add(p, 0.5, hi_u + 0.01, 70, 4); // dropped
  add(p, 0.5, 100, lo - 0.01, 5);  // dropped (top)
  add(p, 0.5, 100, hi_v - 0.01, 6);  // kept (bottom)
  add(p, 0.5, 100, hi_v + 0.01, 7);  // dropped
  const std::vector<float> kept = d::seen_points(view_of(p), kIdentity, {translated(0.5)}, kCamera, kMargin);
  EXPECT_EQ(tags(kept), (std::vector<float>{1, 3, 6}));
  // Rows are copied whole (x, y, z, gray), in order.
  ASSERT_EQ(kept.size(), 12u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(kept[i], p[i]);
}

TEST(TrackingOverlap, AnyEarlierFrameMayHaveSeenAPointAtTheFramesPose) {
  // Two earlier cameras, at x = 0 and x = 1; the frame itself at x = 0.25
  // (its points given in its camera frame).
  std::vector<float> world;
  add(world, 0.0, 4, 70, 1);    // only the camera at 0 would see it, but outside its margin
  add(world, 0.0, 20, 70, 2);   // the camera at 0 sees it
  add(world, 1.0, 180, 70, 3);  // the camera at 1 sees it
  add(world, 1.0, 196, 70, 4);  // right of both
  std::vector<float> local = world;
  for (std::size_t i = 0; i < local.size(); i += 4) local[i] -= 0.25f;
  const std::vector<float> kept =
      d::seen_points(view_of(local), translated(0.25), {kIdentity, translated(1.0)}, kCamera, kMargin);
  EXPECT_EQ(tags(kept), (std::vector<float>{2, 3}));
  // No earlier frame: nothing was seen.
  EXPECT_TRUE(d::seen_points(view_of(local), translated(0.25), {}, kCamera, kMargin).empty());
}

TEST(TrackingOverlap, APointBehindACameraIsNotSeenByIt) {
  // (0, 0, -2) projects to the principal point through the pinhole formula,
  // but lies behind the camera; (0, 0, 0.04) is in front, nearer than 5 cm.
  const std::vector<float> p = {0, 0, -2, 1, 0, 0, 0.04f, 2, 0, 0, 2, 3};
  EXPECT_EQ(tags(d::seen_points(view_of(p), kIdentity, {kIdentity}, kCamera, kMargin)), (std::vector<float>{3}));
}

}  // namespace
