// detail::lower_inverse (core/src/lower_inverse.hpp): the inverse of a 4 x 4
// lower-triangular factor that EM packs every component with, against
// Eigen's triangular solve, whose bits the fits were computed with before.
//
// Kernels: lower_inverse and Eigen's solve are generic code (no SIMD dispatch,
// SOGMM_ISA does not reach them), so the bitwise comparison holds under
// SOGMM_ISA=sse2, avx2 and the default alike; the test runs under each.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <cstring>
#include <random>

#include "lower_inverse.hpp"

namespace {

TEST(LowerInverse, InvertsAHandComputedFactorExactly) {
  // L = [[2,0,0,0],[1,4,0,0],[-2,2,1,0],[0,4,-8,8]]: every entry of L^-1 is
  // a dyadic rational, so the inverse is exact.
  Eigen::Matrix4d l;
  l << 2, 0, 0, 0,  //
      1, 4, 0, 0,   //
      -2, 2, 1, 0,  //
      0, 4, -8, 8;
  Eigen::Matrix4d expected;  // by forward substitution on paper
  expected << 0.5, 0, 0, 0,  //
      -0.125, 0.25, 0, 0,    //
      1.25, -0.5, 1, 0,      //
      1.3125, -0.625, 1, 0.125;
  const Eigen::Matrix4d x = sogmm::detail::lower_inverse(l);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_EQ(x(i, j), expected(i, j)) << i << "," << j;
}

TEST(LowerInverse, MatchesEigensSolveBitForBit) {
  // Cholesky factors of random covariances spanning 12 orders of magnitude
  // per axis (the fit's components range from point-sized seeds to room-sized
  // planes), seeded. A different operation order changes the last bit of
  // some entries: dividing by L_ii instead of multiplying by its reciprocal
  // fails on the first matrix.
  std::mt19937_64 rng(35);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    Eigen::Matrix4d a;
    for (int i = 0; i < 16; ++i) a(i / 4, i % 4) = normal(rng) * std::exp(3.0 * normal(rng));
    Eigen::Matrix4d cov = a * a.transpose();
    for (int i = 0; i < 4; ++i) cov(i, i) += 1e-9;
    const Eigen::LLT<Eigen::Matrix4d> llt(cov);
    if (llt.info() != Eigen::Success) continue;
    const Eigen::Matrix4d l = llt.matrixL();
    const Eigen::Matrix4d want = l.triangularView<Eigen::Lower>().solve(Eigen::Matrix4d::Identity());
    const Eigen::Matrix4d got = sogmm::detail::lower_inverse(l);
    ASSERT_EQ(std::memcmp(want.data(), got.data(), sizeof(double) * 16), 0) << "trial " << trial << "\n" << l;
    ++compared;
  }
  EXPECT_GT(compared, 19000);
}

}  // namespace
