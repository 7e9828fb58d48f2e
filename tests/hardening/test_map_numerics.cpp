// Numerical findings of issue 36 at the C boundary:
// - a map built from frames at rotated poses, fusion off and on, holds
//   exactly symmetric covariances, so sogmm_map_save + sogmm_map_load give
//   back the same model bit for bit (the file stores the symmetric part).
//   A guard: the issue saw a map covariance asymmetric by ~1e-23 (4 entries
//   changed by save + load); this scenario does not reproduce it on 9ad39ee;
// - sogmm_psnr_images_f32 of images that differ is finite at any finite
//   data range (it was +inf at 1e300: data_range^2 overflowed).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "sogmm/sogmm.h"
#include "test_support.hpp"

namespace {

// A wall 2 m x 1.5 m at 2 m depth (48 x 36 points) with gray stripes.
std::vector<float> wall() {
  std::vector<float> p;
  for (int v = 0; v < 36; ++v)
    for (int u = 0; u < 48; ++u)
      p.insert(p.end(), {-1.0f + u / 24.0f, -0.75f + v / 24.0f, 2.0f + 0.01f * ((u * 7 + v * 3) % 5),
                         static_cast<float>((u / 6) % 4) / 4.0f});
  return p;
}

// Camera-to-world pose: rotation by `angle` about the axis (1, 2, 3)/|.| and a translation.
std::vector<double> pose(double angle, double tx) {
  const double n = std::sqrt(14.0), x = 1 / n, y = 2 / n, z = 3 / n, c = std::cos(angle), s = std::sin(angle),
               t = 1 - c;
  return {t * x * x + c,     t * x * y - s * z, t * x * z + s * y, tx,                                        //
          t * x * y + s * z, t * y * y + c,     t * y * z - s * x, 0.5,                                       //
          t * x * z - s * y, t * y * z + s * x, t * z * z + c,     -0.25, 0.0, 0.0, 0.0, 1.0};
}

std::vector<float> covariances(const sogmm_map* map) {
  sogmm_model* m = nullptr;
  EXPECT_EQ(sogmm_map_export(&m, map, nullptr), SOGMM_OK) << sogmm_last_error();
  size_t k = 0;
  EXPECT_EQ(sogmm_model_n_components(m, &k), SOGMM_OK);
  std::vector<float> c(16 * k);
  EXPECT_EQ(sogmm_model_get_covariances_f32(m, c.data(), c.size()), SOGMM_OK);
  sogmm_model_free(m);
  return c;
}

}  // namespace

class MapSymmetry : public ::testing::TestWithParam<int> {};

TEST_P(MapSymmetry, RotatedFramesGiveSymmetricCovariancesAndSaveLoadIsIdentity) {
  const int fusion = GetParam();
  sogmm_options* o = nullptr;
  ASSERT_EQ(sogmm_options_create(&o), SOGMM_OK);
  ASSERT_EQ(sogmm_options_set_i64(o, SOGMM_OPT_MAP_FUSION, fusion), SOGMM_OK);
  sogmm_map* map = nullptr;
  ASSERT_EQ(sogmm_map_create(&map, o), SOGMM_OK) << sogmm_last_error();
  const std::vector<float> frame = wall();
  for (int f = 0; f < 3; ++f) {
    const std::vector<double> p = pose(0.4 + 0.7 * f, 3.0 * f);
    ASSERT_EQ(sogmm_map_insert_points_f32(map, frame.data(), frame.size() / 4, p.data()), SOGMM_OK)
        << sogmm_last_error();
  }
  ASSERT_EQ(sogmm_map_flush(map), SOGMM_OK) << sogmm_last_error();
  const std::vector<float> before = covariances(map);
  ASSERT_GT(before.size(), 16u);
  for (std::size_t k = 0; k < before.size() / 16; ++k)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j)
        ASSERT_EQ(before[16 * k + 4 * i + j], before[16 * k + 4 * j + i]) << "component " << k << " entry " << i << j;

  const std::string path = sogmm::test::make_scratch_dir("sogmm-map-numerics") + "/map.sogmm";
  ASSERT_EQ(sogmm_map_save(map, path.c_str(), o), SOGMM_OK) << sogmm_last_error();
  sogmm_map* loaded = nullptr;
  ASSERT_EQ(sogmm_map_load(&loaded, path.c_str(), o), SOGMM_OK) << sogmm_last_error();
  const std::vector<float> after = covariances(loaded);
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t i = 0; i < after.size(); ++i)
    ASSERT_EQ(after[i], before[i]) << "component " << i / 16 << " entry " << i % 16 << " changed by save + load";
  sogmm_map_free(loaded);
  sogmm_map_free(map);
  sogmm_options_free(o);
}

INSTANTIATE_TEST_SUITE_P(MapNumerics, MapSymmetry, ::testing::Values(0, 1));  // fusion off, on

// MSE of {0, 1} against {1, 1} over 2 valid pixels is 0.5: the honest PSNR
// is 20 log10(range) - 10 log10(0.5), finite for every finite range, also
// where range^2 overflows (1e200, 1.7e308) or underflows (1e-200).
TEST(MapNumerics, PsnrOfDifferentImagesIsFiniteAtAnyDataRange) {
  const float truth[2] = {0.0f, 1.0f}, estimate[2] = {1.0f, 1.0f};
  for (double range : {1.0, 1e200, 1.7e308, 1e-200}) {
    double psnr = 0.0;
    ASSERT_EQ(sogmm_psnr_images_f32(truth, estimate, 2, range, &psnr, nullptr), SOGMM_OK) << sogmm_last_error();
    EXPECT_TRUE(std::isfinite(psnr)) << range;
    EXPECT_NEAR(psnr, 20.0 * std::log10(range) + 10.0 * std::log10(2.0), 1e-9 * (1.0 + std::fabs(psnr))) << range;
  }
  double same = 0.0;
  ASSERT_EQ(sogmm_psnr_images_f32(truth, truth, 2, 1e300, &same, nullptr), SOGMM_OK);
  EXPECT_EQ(same, INFINITY);  // identical images: +infinity, as documented
}
