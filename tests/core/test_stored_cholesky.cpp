// sogmm::stored_cholesky, the library's one positive-definiteness test: the
// arithmetic of spec/format.md step 19d, checked on hand-computed cases.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "covariance_storage.hpp"
#include "sogmm/inference.hpp"

#include "sogmm/gmm.hpp"

namespace {

TEST(StoredCholesky, FactorsAHandComputedMatrixExactly) {
  // L = [[2,0,0,0],[1,3,0,0],[-1,2,1,0],[0,1,-2,4]]; a = L L^T in integers,
  // so every step of the factorisation is exact.
  const double a[16] = {4, 2, -2, 0,  //
                        2, 10, 5, 3,  //
                        -2, 5, 6, 0,  //
                        0, 3, 0, 21};
  const double expected[16] = {2, 0, 0, 0, 1, 3, 0, 0, -1, 2, 1, 0, 0, 1, -2, 4};
  double l[16];
  ASSERT_TRUE(sogmm::stored_cholesky(a, l));
  for (int i = 0; i < 16; ++i) EXPECT_EQ(l[i], expected[i]) << "entry " << i;
}

TEST(StoredCholesky, ReadsOnlyTheLowerTriangle) {
  // The upper triangle holds garbage (the spec: only entries on and below the
  // diagonal are read).
  const double a[16] = {4, 1e300, NAN, -7,  //
                        2, 10, INFINITY, 0,  //
                        -2, 5, 6, 1,  //
                        0, 3, 0, 21};
  EXPECT_TRUE(sogmm::stored_cholesky(a));
}

TEST(StoredCholesky, RejectsZeroNegativeAndNanPivots) {
  const double zero_pivot[16] = {1, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // d1 = 1 - 1 = 0
  EXPECT_FALSE(sogmm::stored_cholesky(zero_pivot));
  const double negative[16] = {1, 0, 0, 0, 0, -1e-300, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_FALSE(sogmm::stored_cholesky(negative));
  const double nan_entry[16] = {1, 0, 0, 0, 0, 1, 0, 0, NAN, 0, 1, 0, 0, 0, 0, 1};
  EXPECT_FALSE(sogmm::stored_cholesky(nan_entry));
}

TEST(StoredCholesky, SubtractsEachProductInTurnAsTheSpecSays) {
  // With l00 = l11 = 1 and l10 = 0, pivot 2 is a22 - l20^2 - l21^2 with
  // l20 = x, l21 = y. For these values (found by a search over a22 near
  // x^2 + y^2) subtracting in turn leaves one ulp of 1 > 0, while
  // a22 - (x^2 + y^2) is exactly 0: the two orders disagree, and the spec
  // (and so every reader) takes the first.
  const double x = 0.6138354903459564, y = 0.7894334726951968, a22 = 0.9999992170198588;
  ASSERT_GT((a22 - x * x) - y * y, 0.0);
  ASSERT_EQ(a22 - (x * x + y * y), 0.0);
  const double a[16] = {1, 0, 0, 0,  //
                        0, 1, 0, 0,  //
                        x, y, a22, 0,  //
                        0, 0, 0, 1};
  double l[16];
  ASSERT_TRUE(sogmm::stored_cholesky(a, l));
  EXPECT_EQ(l[10], std::sqrt((a22 - x * x) - y * y));
}

TEST(StoredCholesky, CovarianceStorageAcceptsATargetOnlyEigenFactors) {
  // The EM makes its covariances positive definite by Eigen's LLT, which
  // subtracts a summed square (a22 - (x^2 + y^2) > 0 here) where the spec
  // subtracts in turn (exactly 0): store_covariance must still store it (by
  // the eigenvalue floor), not throw (found in review).
  const double x = 0.6790183630976147, y = 0.7341212663503303, a22 = 0.9999999711315767;
  const double a[16] = {1, 0, x, 0,  //
                        0, 1, y, 0,  //
                        x, y, a22, 0,  //
                        0, 0, 0, 1};
  ASSERT_FALSE(sogmm::stored_cholesky(a));
  const Eigen::LLT<Eigen::Matrix4d> llt(Eigen::Map<const Eigen::Matrix4d>(a).eval());
  ASSERT_EQ(llt.info(), Eigen::Success);
  float out[16];
  ASSERT_NO_THROW(sogmm::detail::store_covariance(a, out));
  double stored[16];
  for (int i = 0; i < 16; ++i) stored[i] = out[i];
  EXPECT_TRUE(sogmm::stored_cholesky(stored));
}

TEST(StoredCholesky, AModelValidByItsSymmetricPartCanBeQueried) {
  // Asymmetric within validate's tolerance (1e-5): the lower triangle alone
  // (c32 = 1 + 5e-7) is not positive definite, the symmetric part
  // (1 - 4.25e-6) is, and that is what validate tests and a file holds, so
  // sampling and scoring must use it too (found in review).
  sogmm::Gmm g;
  g.resize(1);
  g.weights[0] = 1.0f;
  for (int i = 0; i < 4; ++i) g.means[i] = 0.0f;
  for (int i = 0; i < 16; ++i) g.covariances[i] = (i % 5 == 0) ? 1.0f : 0.0f;
  g.covariances[4 * 2 + 3] = 1.0f - 9e-6f;  // c23 (upper)
  g.covariances[4 * 3 + 2] = 1.0f + 5e-7f;  // c32 (lower)
  g.support_size = 1;
  ASSERT_NO_THROW(sogmm::validate(g));
  double lower[16];
  for (int i = 0; i < 16; ++i) lower[i] = g.covariances[i];
  ASSERT_FALSE(sogmm::stored_cholesky(lower));
  std::vector<float> pts(4 * 50);
  ASSERT_NO_THROW(sogmm::sample(g, 50, 1, 4, pts.data()));
  for (float v : pts) EXPECT_TRUE(std::isfinite(v));
  std::vector<double> scores(50);
  ASSERT_NO_THROW(sogmm::score_samples(g, pts.data(), 50, 4, scores.data()));
  for (double v : scores) EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
