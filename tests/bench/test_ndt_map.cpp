#include <gtest/gtest.h>

#include <cmath>

#include "ndt_map.hpp"
#include "plane.hpp"
#include "sogmm/error.hpp"
#include "sogmm/metrics.hpp"

namespace sogmm::bench {
namespace {

using test::plane_camera;
using test::plane_cloud;

PsnrResult psnr_of(const NdtMap& map, const PointsView& truth) {
  std::vector<float> gray(truth.size), est(truth.size);
  for (std::size_t i = 0; i < truth.size; ++i) {
    gray[i] = truth[i][3];
    est[i] = map.gray_at(truth[i]);
  }
  const auto t = project_to_image(truth, gray.data(), plane_camera());
  const auto e = project_to_image(truth, est.data(), plane_camera());
  return psnr_images(t.data(), e.data(), t.size());
}

TEST(ProportionalAllocation, SumsToNAndIsExactForEqualTotals) {
  EXPECT_EQ(proportional_allocation({1, 2, 3}, 6), (std::vector<std::size_t>{1, 2, 3}));
  EXPECT_EQ(proportional_allocation({1, 2, 3}, 3), (std::vector<std::size_t>{1, 1, 1}));
  EXPECT_EQ(proportional_allocation({5, 5}, 1), (std::vector<std::size_t>{1, 0}));
  EXPECT_EQ(proportional_allocation({}, 4), (std::vector<std::size_t>{}));
  std::size_t sum = 0;
  for (std::size_t v : proportional_allocation({7, 11, 13, 1}, 1000)) sum += v;
  EXPECT_EQ(sum, 1000u);
}

TEST(NdtMap, PlaneCellsHaveKnownCountsMeansAndCovariances) {
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  NdtMap map(0.02);
  map.build(cloud.view());
  ASSERT_EQ(map.size(), 900u);
  EXPECT_EQ(map.paper_bytes(), 4u * 900 * 10);
  // Offsets within a cell: -7.5, -2.5, 2.5, 7.5 mm -> variance 3.125e-5 m^2.
  for (const NdtCell& c : map.cells()) {
    EXPECT_EQ(c.count, 16u);
    EXPECT_NEAR(c.mean[0], (c.ix + 0.5) * 0.02, 1e-6);
    EXPECT_NEAR(c.mean[1], (c.iy + 0.5) * 0.02, 1e-6);
    EXPECT_NEAR(c.mean[2], test::kZ, 1e-6);
    EXPECT_NEAR(c.cov[0], 3.125e-5, 1e-9);
    EXPECT_NEAR(c.cov[3], 3.125e-5, 1e-9);
    EXPECT_NEAR(c.cov[1], 0.0, 1e-9);
    EXPECT_NEAR(c.cov[5], 0.0, 1e-9);
    EXPECT_DOUBLE_EQ(c.gray, 0.5);
  }
}

TEST(NdtMap, ConstantGrayGivesExactPsnr) {
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  for (double voxel : {0.02, 0.05}) {
    NdtMap map(voxel);
    map.build(cloud.view());
    const PsnrResult p = psnr_of(map, cloud.view());
    EXPECT_EQ(p.mse, 0.0);
    EXPECT_TRUE(std::isinf(p.psnr));
    EXPECT_TRUE(std::isinf(p.psnr_paper));
  }
}

TEST(NdtMap, VoxelAlignedGrayStepIsExact) {
  // Left half 0.25, right half 0.75; x = 0 is a voxel boundary at both sizes.
  const PointCloud cloud = plane_cloud([](double x, double) { return x < 0 ? 0.25f : 0.75f; });
  NdtMap map(0.02);
  map.build(cloud.view());
  std::size_t fallbacks = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(map.gray_at(cloud.view()[i], &fallbacks), cloud.view()[i][3]);
  EXPECT_EQ(fallbacks, 0u);
  // A point outside every voxel takes the nearest occupied voxel's gray.
  const float far_right[3] = {5.0f, 0.0f, 1.01f}, far_left[3] = {-5.0f, 0.1f, 1.0f};
  EXPECT_EQ(map.gray_at(far_right, &fallbacks), 0.75f);
  EXPECT_EQ(map.gray_at(far_left, &fallbacks), 0.25f);
  EXPECT_EQ(fallbacks, 2u);
}

TEST(NdtMap, SamplesOfAPlaneStayOnItWithinTheVoxelSize) {
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  for (double voxel : {0.02, 0.05}) {
    NdtMap map(voxel);
    map.build(cloud.view());
    const std::vector<float> s = map.sample(cloud.size(), 7);
    ASSERT_EQ(s.size(), 3 * cloud.size());
    // Off-plane spread: eigenvalue floor max/100 -> std <= 0.1 * in-plane std.
    double max_dz = 0.0;
    for (std::size_t i = 0; i < cloud.size(); ++i) max_dz = std::max(max_dz, std::fabs(s[3 * i + 2] - test::kZ));
    EXPECT_LT(max_dz, 0.1 * voxel);
    const ReconstructionResult r = compare_clouds(s.data(), cloud.size(), 3, cloud.view(), 0.01);
    EXPECT_LT(r.mre, 0.5 * voxel) << "voxel " << voxel;
    EXPECT_LT(r.mre, 0.005);
    EXPECT_GT(r.fscore, 0.9);
    EXPECT_EQ(map.sample(cloud.size(), 7), s);  // deterministic in the seed
  }
}

TEST(NdtMap, SinglePointCellSamplesAtThePoint) {
  const std::vector<float> pts = {0.101f, 0.203f, 1.5f, 0.4f};
  NdtMap map(0.05);
  map.build(PointsView{pts.data(), 1});
  ASSERT_EQ(map.size(), 1u);
  const std::vector<float> s = map.sample(3, 1);
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(s[3 * k + a], pts[a], 1e-6);
}

TEST(NdtMap, RejectsBadInput) {
  EXPECT_THROW(NdtMap(0.0), Error);
  EXPECT_THROW(NdtMap(-1.0), Error);
  const std::vector<float> nan = {NAN, 0, 1, 0.5f};
  NdtMap map(0.02);
  EXPECT_THROW(map.build(PointsView{nan.data(), 1}), Error);
  const float q[3] = {0, 0, 1};
  EXPECT_THROW(map.gray_at(q), Error);  // empty map
}

}  // namespace
}  // namespace sogmm::bench
