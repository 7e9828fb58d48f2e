#include <gtest/gtest.h>

#include <cmath>

#include "octomap_adapter.hpp"
#include "plane.hpp"
#include "sogmm/error.hpp"
#include "sogmm/metrics.hpp"

namespace sogmm::bench {
namespace {

using test::plane_camera;
using test::plane_cloud;

#define REQUIRE_OCTOMAP()                                                  \
  if (!octomap_available()) GTEST_SKIP() << "built without liboctomap"

TEST(OctoMapAdapter, UnavailableMeansThrowing) {
  if (octomap_available()) GTEST_SKIP() << "OctoMap is built in";
  EXPECT_THROW(OctoMapModel(0.02), Error);
}

TEST(OctoMapAdapter, PlaneLeavesAndExactPsnr) {
  REQUIRE_OCTOMAP();
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  OctoMapModel map(0.02);
  map.build(cloud.view());
  EXPECT_EQ(map.occupied_leaves(), 900u);  // 30 x 30 voxels, all hit
  std::vector<float> gray(cloud.size()), est(cloud.size());
  std::size_t fallbacks = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    gray[i] = cloud.view()[i][3];
    est[i] = map.gray_at(cloud.view()[i], &fallbacks);
  }
  EXPECT_EQ(fallbacks, 0u);
  const auto t = project_to_image(cloud.view(), gray.data(), plane_camera());
  const auto e = project_to_image(cloud.view(), est.data(), plane_camera());
  const PsnrResult p = psnr_images(t.data(), e.data(), t.size());
  EXPECT_EQ(p.mse, 0.0);
  EXPECT_TRUE(std::isinf(p.psnr));
}

TEST(OctoMapAdapter, GrayIsTheExactMeanNotEightBit) {
  REQUIRE_OCTOMAP();
  // 0.3 * 255 = 76.5: an 8-bit node colour could not return 0.3.
  const PointCloud cloud = plane_cloud([](double x, double) { return x < 0 ? 0.3f : 0.7f; });
  OctoMapModel map(0.05);
  map.build(cloud.view());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_EQ(map.gray_at(cloud.view()[i]), cloud.view()[i][3]);
  std::size_t fallbacks = 0;
  const float far_left[3] = {-3.0f, 0.0f, 1.01f};
  EXPECT_EQ(map.gray_at(far_left, &fallbacks), 0.3f);
  // Between the camera and the plane the space is free: nearest occupied leaf.
  const float in_free_space[3] = {0.2f, 0.0f, 0.5f};
  EXPECT_EQ(map.gray_at(in_free_space, &fallbacks), 0.7f);
  EXPECT_EQ(fallbacks, 2u);
}

TEST(OctoMapAdapter, ReconstructionIsLeafCentresWithinTheVoxelSize) {
  REQUIRE_OCTOMAP();
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  for (double res : {0.02, 0.05}) {
    OctoMapModel map(res);
    map.build(cloud.view());
    const std::vector<float> r = map.reconstruct(cloud.size());
    ASSERT_EQ(r.size(), 3 * cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      // Centres of voxels [k res, (k+1) res): odd multiples of res / 2.
      for (int a = 0; a < 3; ++a) {
        const double k = r[3 * i + a] / res - 0.5;
        ASSERT_NEAR(k, std::round(k), 1e-4);
      }
    }
    const ReconstructionResult m = compare_clouds(r.data(), cloud.size(), 3, cloud.view(), 0.01);
    EXPECT_LT(m.mre, res);
    if (res == 0.02) {
      EXPECT_NEAR(m.mre, std::sqrt(2.0) * 0.0025, 1e-5);  // centre to nearest grid point
    }
  }
}

TEST(OctoMapAdapter, WritesAnOtFileOfPlausibleSize) {
  REQUIRE_OCTOMAP();
  const PointCloud cloud = plane_cloud([](double, double) { return 0.5f; });
  OctoMapModel fine(0.02), coarse(0.05);
  fine.build(cloud.view());
  coarse.build(cloud.view());
  const std::uint64_t a = fine.file_bytes(), b = coarse.file_bytes();
  EXPECT_GT(a, 900u * 4);  // at least a float per occupied leaf
  EXPECT_GT(a, b);
  EXPECT_EQ(fine.file_bytes(), a);  // deterministic
}

TEST(OctoMapAdapter, RejectsBadInput) {
  REQUIRE_OCTOMAP();
  EXPECT_THROW(OctoMapModel(0.0), Error);
  OctoMapModel map(0.02);
  EXPECT_THROW(map.build(PointsView{nullptr, 0}), Error);
}

}  // namespace
}  // namespace sogmm::bench
