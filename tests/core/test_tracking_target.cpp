// What tracking registers a frame to (core/src/tracking_target.hpp): cell
// Gaussians of points against hand-computed moments, and the map's
// components joined by its pending points' cells with weights by support.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "map_test_util.hpp"
#include "tracking_target.hpp"

namespace {

using namespace sogmm_test;
namespace d = sogmm::detail;

sogmm::PointsView view_of(const std::vector<float>& p) { return {p.data(), p.size() / 4, false}; }

// The 2 x 2 x 2 corners of a box inside cell (0, 0, 0) of 6 cm: x, y in
// {1, 3} cm, z in {2, 4} cm, gray 0.5 + x: mean (2, 2, 3) cm, gray 0.52;
// per axis variance 1e-4 m^2, gray covaries with x exactly (1e-4).
std::vector<float> corners() {
  std::vector<float> p;
  for (double x : {0.01, 0.03})
    for (double y : {0.01, 0.03})
      for (double z : {0.02, 0.04})
        p.insert(p.end(), {float(x), float(y), float(z), float(0.5 + x)});
  return p;
}

TEST(TrackingTarget, CellGaussianHasTheCellsMomentsPlusTheFloors) {
  std::vector<float> p = corners();
  // Five points in another cell: fewer than the minimum, left out.
  for (int i = 0; i < 5; ++i) p.insert(p.end(), {0.5f + 0.01f * float(i), 0.5f, 0.5f, 0.1f});
  const sogmm::Gmm g = d::cell_gaussians(view_of(p), 0.06, 6);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g.support_size, 8u);
  EXPECT_FLOAT_EQ(g.weights[0], 1.0f);
  const double mean[4] = {0.02, 0.02, 0.03, 0.52};
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(g.mean(0)[i], mean[i], 1e-7);
  const float* c = g.covariance(0);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(c[5 * i], 1e-4 + d::kPendingCellSpatialFloor, 1e-9);
  EXPECT_NEAR(c[15], 1e-4 + d::kPendingCellGrayFloor, 1e-9);
  EXPECT_NEAR(c[3], 1e-4, 1e-9);   // x-gray
  EXPECT_NEAR(c[12], 1e-4, 1e-9);  // symmetric
  EXPECT_NEAR(c[1], 0.0, 1e-9);    // x-y: a full factorial, uncorrelated
  EXPECT_NEAR(c[6], 0.0, 1e-9);    // y-z
  // No cell holds six points: nothing.
  EXPECT_EQ(d::cell_gaussians(view_of(p), 0.06, 9).size(), 0u);
}

// A 40 x 40 cm plane z = depth in front of the camera, points 1 cm apart, gray
// varying along x.
std::vector<float> plane(double depth) {
  std::vector<float> p;
  for (int a = 0; a < 40; ++a)
    for (int b = 0; b < 40; ++b)
      p.insert(p.end(), {float(-0.2 + 0.01 * a), float(-0.2 + 0.01 * b), float(depth), float(0.2 + 0.015 * a)});
  return p;
}

TEST(TrackingTarget, PendingPointsJoinTheComponentsBySupport) {
  MapOptions o;
  o.batch_size = 100000;  // nothing flushes by itself
  Map map(o);
  const std::vector<float> a = plane(1.0), b = plane(1.0);
  map.insert_points(view_of(a), kIdentity);
  map.flush();
  const sogmm::Gmm components = map.model().gmm;
  EXPECT_EQ(d::tracking_target(map).size(), components.size());  // nothing pending: the components
  // The same plane 2 m further along x: all of it novel, all of it pending.
  map.insert_points(view_of(b), translated(2.0));
  ASSERT_EQ(map.pending(), 1600u);
  const sogmm::PointCloud pending = map.pending_points();
  ASSERT_EQ(pending.size(), 1600u);
  for (std::size_t i = 0; i < pending.size(); ++i) {
    EXPECT_NEAR(pending.xyzg[4 * i], b[4 * i] + 2.0, 1e-6);
    EXPECT_EQ(pending.xyzg[4 * i + 1], b[4 * i + 1]);
    EXPECT_EQ(pending.xyzg[4 * i + 3], b[4 * i + 3]);
  }
  const sogmm::Gmm cells = d::cell_gaussians(pending.view(), d::kPendingCell, d::kPendingCellMin);
  const sogmm::Gmm target = d::tracking_target(map);
  ASSERT_EQ(target.size(), components.size() + cells.size());
  const double s = double(components.support_size), p = double(cells.support_size);
  EXPECT_EQ(target.support_size, components.support_size + cells.support_size);
  double sum = 0.0, sum_cells = 0.0;
  for (std::size_t k = 0; k < target.size(); ++k) {
    sum += target.weights[k];
    if (k >= components.size()) sum_cells += target.weights[k];
  }
  EXPECT_NEAR(sum, 1.0, 1e-5);
  EXPECT_NEAR(sum_cells, p / (s + p), 1e-5);
  EXPECT_EQ(target.means[4 * components.size()], cells.means[0]);
  EXPECT_NO_THROW(sogmm::validate(target));
}

}  // namespace
