// A model the C API accepts can always be saved (fuzz_api's round-trip
// invariant): the positive definiteness check of sogmm::validate runs on the
// symmetric part of each covariance rounded to float32, which is what the
// writer checks and a reader returns (spec/format.md 5.1). Before, it ran on
// the lower triangle only, and fuzz_api found an asymmetric covariance (within
// the symmetry tolerance) that from_arrays accepted but no save could write
// (tests/fuzz/regressions/api/from_arrays_asymmetric_not_spd_when_saved).
#include <gtest/gtest.h>

#include <array>
#include <string>

#include "sogmm/sogmm.h"

namespace {

// The fuzz finding's covariance: PD on its lower triangle (c32 = 0), but the
// symmetric part's 2 x 2 block [[4.7e-41, 1.3e-9], [1.3e-9, 0.01]] has a
// negative determinant (4.7e-43 - 1.7e-18).
std::array<float, 16> finding(float c22) {
  return {0.51f, -0.008f, 0.0f, 0.0f,  //
          -0.008f, 7.76f, 0.0f, 0.0f,  //
          0.0f, 0.0f, c22, 2.5784852e-09f,  //
          0.0f, 0.0f, 0.0f, 0.01f};
}

sogmm_status make(const std::array<float, 16>& cov, sogmm_model** out) {
  const float w = 1.0f, mu[4] = {0.0f, 0.0f, 1.0f, 0.5f};
  return sogmm_model_from_arrays_f32(out, 1, &w, mu, cov.data(), 100);
}

TEST(CapiStoredCovariance, AsymmetricCovarianceWhoseSymmetricPartIsNotPositiveDefiniteIsRefused) {
  sogmm_model* m = reinterpret_cast<sogmm_model*>(1);
  const sogmm_status s = make(finding(4.66352129e-41f), &m);
  EXPECT_NE(s, SOGMM_OK);
  EXPECT_EQ(m, nullptr) << "a failed call wrote its output";
  EXPECT_NE(std::string(sogmm_last_error()).find("not positive definite"), std::string::npos) << sogmm_last_error();
}

TEST(CapiStoredCovariance, AsymmetryWithinTheToleranceIsStillAcceptedAndSaved) {
  // The same asymmetry on a well-conditioned block: accepted as before, and
  // the file holds the symmetric part.
  sogmm_model* m = nullptr;
  ASSERT_EQ(make(finding(1.0f), &m), SOGMM_OK) << sogmm_last_error();
  sogmm_buffer* buf = nullptr;
  ASSERT_EQ(sogmm_model_save_to_memory(&buf, m, nullptr), SOGMM_OK) << sogmm_last_error();
  sogmm_model* back = nullptr;
  ASSERT_EQ(sogmm_model_load_from_memory(&back, sogmm_buffer_data(buf), sogmm_buffer_size(buf), nullptr), SOGMM_OK);
  float cov[16];
  ASSERT_EQ(sogmm_model_get_covariances_f32(back, cov, 16), SOGMM_OK);
  EXPECT_EQ(cov[2 * 4 + 3], static_cast<float>(2.5784852e-09 / 2.0));
  EXPECT_EQ(cov[3 * 4 + 2], cov[2 * 4 + 3]);
  sogmm_model_free(back);
  sogmm_buffer_free(buf);
  sogmm_model_free(m);
}

}  // namespace
