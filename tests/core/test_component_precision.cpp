// Components rounded to their own precision (component_precision.hpp,
// MapOptions::component_precision; issue 33): the bounds it states, checked
// against an independent eigen-decomposition, and the zero low bits it is for.
// No SIMD kernel runs here (the rounding is scalar binary64 with ldexp and
// nearbyint, SOGMM_ISA selects only the EM kernels), so the bounds hold alike
// under sse2, avx2 and AVX-512; the 1e-9 slack covers the checking Eigen
// decomposition's own rounding on matrices of condition number <= 1e4.
// Mutations tried: a mean grid 4x coarser fails the mean bound, a covariance
// grid 4x coarser the eigenvalue bounds and the hand case.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>

#include "component_precision.hpp"

namespace {

// m components: rotated thin and round covariances (eigenvalues from 1e-6 to
// 1e-2 m^2, gray 1e-4 to 1e-2), means up to 4 m away, seeded.
sogmm::Gmm components(std::size_t m, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sogmm::Gmm g;
  for (std::size_t k = 0; k < m; ++k) {
    g.weights.push_back(1.0f / static_cast<float>(m));
    for (int i = 0; i < 3; ++i) g.means.push_back(static_cast<float>(8 * u(rng) - 4));
    g.means.push_back(static_cast<float>(u(rng)));
    const Eigen::Matrix4d q = Eigen::Matrix4d::Random().householderQr().householderQ();
    Eigen::Vector4d ev;
    ev << 1e-2 * u(rng) + 1e-4, 1e-3 * u(rng) + 1e-5, std::pow(10.0, -6 + 2 * u(rng)), 1e-4 + 1e-2 * u(rng);
    const Eigen::Matrix4d s = q * ev.asDiagonal() * q.transpose();
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) g.covariances.push_back(static_cast<float>(i <= j ? s(i, j) : s(j, i)));
  }
  g.support_size = 1000;
  return g;
}

Eigen::Matrix4d cov_of(const sogmm::Gmm& g, std::size_t k) {
  Eigen::Matrix4d s;
  for (int i = 0; i < 16; ++i) s(i / 4, i % 4) = g.covariance(k)[i];
  return s;
}

int trailing_zero_bits(float f) {
  std::uint32_t b;
  std::memcpy(&b, &f, 4);
  int n = 0;
  while (n < 23 && ((b >> n) & 1u) == 0) ++n;
  return n;
}

TEST(ComponentPrecisionTest, MovesEachComponentByAtMostThePrecisionInItsOwnMetric) {
  srand(7);  // Eigen::Random
  const sogmm::Gmm g = components(300, 11);
  for (double p : {0.05, 0.25, 0.5}) {
    const sogmm::Gmm r = sogmm::detail::round_to_precision(g, p);
    ASSERT_EQ(r.size(), g.size());
    EXPECT_EQ(std::memcmp(r.weights.data(), g.weights.data(), 4 * g.size()), 0) << "weights are not touched";
    double zero_bits = 0;
    for (std::size_t k = 0; k < g.size(); ++k) {
      const Eigen::Matrix4d s = cov_of(g, k), s2 = cov_of(r, k);
      const Eigen::LLT<Eigen::Matrix4d> llt(s);
      const Eigen::Matrix4d l_inv = llt.matrixL().solve(Eigen::Matrix4d::Identity());
      // Eigenvalues of L^-1 S' L^-T within 1 +- p (positive definite).
      const Eigen::Vector4d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(l_inv * s2 * l_inv.transpose())
                                     .eigenvalues();
      EXPECT_GE(ev.minCoeff(), 1 - p - 1e-9) << k;
      EXPECT_LE(ev.maxCoeff(), 1 + p + 1e-9) << k;
      EXPECT_TRUE((s2 - s2.transpose()).isZero(0)) << "symmetric entries round alike";
      Eigen::Vector4d d;
      for (int i = 0; i < 4; ++i) d(i) = static_cast<double>(r.mean(k)[i]) - g.mean(k)[i];
      EXPECT_LE((l_inv * d).norm(), p + 1e-9) << "mean moved by more than p standard deviations, " << k;
      for (int i = 0; i < 4; ++i) zero_bits += trailing_zero_bits(r.mean(k)[i]) - trailing_zero_bits(g.mean(k)[i]);
    }
    // The point: low mantissa bits become zero (x, y, z up to 4 m on grids
    // of a fraction of the thinnest standard deviation, >= 1e-3 m here).
    EXPECT_GT(zero_bits / (4.0 * g.size()), p >= 0.25 ? 6.0 : 3.0) << p;
  }
}

TEST(ComponentPrecisionTest, ZeroIsOffAndRoundingIsOnPowerOfTwoGrids) {
  const sogmm::Gmm g = components(20, 3);
  const sogmm::Gmm off = sogmm::detail::round_to_precision(g, 0.0);
  EXPECT_EQ(std::memcmp(off.means.data(), g.means.data(), 4 * g.means.size()), 0);
  EXPECT_EQ(std::memcmp(off.covariances.data(), g.covariances.data(), 4 * g.covariances.size()), 0);
  // Hand case: S = diag(1e-4, 1e-4, 1e-4, 1e-2): t = 3e4 + 1e2; p = 0.25:
  // mean grid 2^floor(log2(0.25 / sqrt(30100))) = 2^-10 (0.25/173.5 = 1.44e-3),
  // covariance grid 2^floor(log2(0.25 / 60200)) = 2^-18 (4.15e-6).
  sogmm::Gmm h;
  h.weights = {1.0f};
  h.means = {1.2345678f, -0.3333333f, 2.7182817f, 0.5f};
  h.covariances = {1e-4f, 0, 0, 0, 0, 1e-4f, 0, 0, 0, 0, 1e-4f, 0, 0, 0, 0, 1e-2f};
  h.support_size = 1;
  const sogmm::Gmm r = sogmm::detail::round_to_precision(h, 0.25);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(r.means[i], static_cast<float>(std::nearbyint(h.means[i] * 1024.0) / 1024.0)) << i;
  for (int i = 0; i < 16; ++i)
    EXPECT_EQ(r.covariances[i], static_cast<float>(std::nearbyint(h.covariances[i] * 262144.0) / 262144.0)) << i;
}

}  // namespace
