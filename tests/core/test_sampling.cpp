// sample(): mean and covariance within statistical bounds, with the variance of
// the truncated standard normal computed in closed form; truncation honoured.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <vector>

#include "sogmm/inference.hpp"
#include "test_util.hpp"

using sogmm_test::cov_of;
using sogmm_test::mean_of;
using sogmm_test::set_component;

namespace {

// Variance of a standard normal truncated to (-a, a):
// 1 - 2 a phi(a) / (2 Phi(a) - 1), with 2 Phi(a) - 1 = erf(a / sqrt 2).
double truncated_variance(double a) {
  if (std::isinf(a)) return 1.0;
  const double phi = std::exp(-0.5 * a * a) / std::sqrt(2.0 * M_PI);
  return 1.0 - 2.0 * a * phi / std::erf(a / std::sqrt(2.0));
}

sogmm::Gmm one_component() {
  sogmm::Gmm g;
  g.resize(1);
  Eigen::Matrix4d c;
  c << 0.04, 0.012, -0.006, 0.004,  //
      0.012, 0.03, 0.005, -0.003,   //
      -0.006, 0.005, 0.05, 0.002,   //
      0.004, -0.003, 0.002, 0.01;
  set_component(g, 0, 1.0, Eigen::Vector4d(0.5, -0.2, 1.5, 0.4), c);
  return g;
}

struct Moments {
  Eigen::Vector4d mean = Eigen::Vector4d::Zero();
  Eigen::Matrix4d cov = Eigen::Matrix4d::Zero();
};
Moments moments(const std::vector<float>& x, int dims) {
  const std::size_t n = x.size() / dims;
  Moments m;
  for (std::size_t i = 0; i < n; ++i)
    for (int d = 0; d < dims; ++d) m.mean(d) += x[dims * i + d];
  m.mean /= static_cast<double>(n);
  for (std::size_t i = 0; i < n; ++i)
    for (int a = 0; a < dims; ++a)
      for (int b = 0; b < dims; ++b)
        m.cov(a, b) += (x[dims * i + a] - m.mean(a)) * (x[dims * i + b] - m.mean(b));
  m.cov /= static_cast<double>(n);
  return m;
}

void check_single_component(double truncation) {
  const sogmm::Gmm g = one_component();
  const std::size_t n = 200000;
  std::vector<float> x(4 * n);
  sogmm::sample(g, n, 42, 4, x.data(), truncation);
  const double s2 = truncated_variance(truncation);
  const Eigen::Matrix4d sigma = cov_of(g, 0), expected = s2 * sigma;
  const Eigen::Vector4d mu = mean_of(g, 0);
  const Moments m = moments(x, 4);
  for (int a = 0; a < 4; ++a) {
    // 5 standard errors; the truncated law has a lower kurtosis than the normal,
    // so the normal-theory standard errors are conservative.
    EXPECT_NEAR(m.mean(a), mu(a), 5.0 * std::sqrt(expected(a, a) / n)) << "mean " << a;
    for (int b = 0; b < 4; ++b) {
      const double se = std::sqrt((expected(a, a) * expected(b, b) + expected(a, b) * expected(a, b)) / n);
      EXPECT_NEAR(m.cov(a, b), expected(a, b), 6.0 * se) << "cov (" << a << "," << b << "), truncation "
                                                         << truncation << ", factor " << s2;
    }
  }
  // Whitened coordinates z = L^-1 (x - mu), L = lower Cholesky factor.
  const Eigen::Matrix4d l = sigma.llt().matrixL();
  double zmax = 0.0;
  std::size_t beyond = 0;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector4d v(x[4 * i], x[4 * i + 1], x[4 * i + 2], x[4 * i + 3]);
    const Eigen::Vector4d z = l.triangularView<Eigen::Lower>().solve(v - mu);
    zmax = std::max(zmax, z.cwiseAbs().maxCoeff());
    beyond += (z.cwiseAbs().array() > 2.6).count();
  }
  if (std::isinf(truncation)) {
    // P(|z| > 2.6) = 0.932%; 800k coordinates -> ~7450 expected.
    EXPECT_GT(beyond, 6000u) << "untruncated sampler never leaves the 2.6-sigma box";
    EXPECT_GT(zmax, 3.5);
  } else {
    EXPECT_LT(zmax, truncation + 1e-3) << "a coordinate of z exceeds the truncation";
    EXPECT_EQ(beyond, 0u);
  }
}

}  // namespace

TEST(Sample, TruncatedVarianceClosedFormSanity) {
  // Independent numeric check of the closed form: midpoint integration.
  double num = 0.0, den = 0.0;
  const int steps = 200000;
  const double h = 5.0 / steps;
  for (int i = 0; i < steps; ++i) {
    const double z = -2.5 + (i + 0.5) * h, p = std::exp(-0.5 * z * z);
    num += z * z * p;
    den += p;
  }
  EXPECT_NEAR(truncated_variance(2.5), num / den, 1e-9);
  EXPECT_NEAR(truncated_variance(2.5), 0.911256, 1e-6);  // 1 - 5 phi(2.5) / erf(2.5 / sqrt 2)
}

TEST(Sample, SingleComponentMomentsTruncatedAt2p5) { check_single_component(2.5); }

TEST(Sample, SingleComponentMomentsUntruncated) {
  check_single_component(std::numeric_limits<double>::infinity());
}

TEST(Sample, DefaultTruncationIs2p5) {
  const sogmm::Gmm g = one_component();
  const std::size_t n = 5000;
  std::vector<float> a(4 * n), b(4 * n);
  sogmm::sample(g, n, 9, 4, a.data());
  sogmm::sample(g, n, 9, 4, b.data(), 2.5);
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
}

TEST(Sample, MixtureCountsAndGrouping) {
  // Three components 20+ sigma apart: classify samples by nearest mean.
  sogmm::Gmm g;
  g.resize(3);
  const double w[3] = {0.2, 0.3, 0.5};
  const Eigen::Vector4d mus[3] = {{0, 0, 1, 0.2}, {2, 0, 1, 0.5}, {0, 2, 2, 0.8}};
  for (int k = 0; k < 3; ++k)
    set_component(g, k, w[k], mus[k], (0.0004 + 0.0002 * k) * Eigen::Matrix4d::Identity());
  const std::size_t n = 100000;
  std::vector<float> x(4 * n);
  sogmm::sample(g, n, 5, 4, x.data());
  std::vector<int> label(n);
  std::size_t counts[3] = {0, 0, 0};
  Eigen::Vector4d sums[3] = {Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector4d v(x[4 * i], x[4 * i + 1], x[4 * i + 2], x[4 * i + 3]);
    int best = 0;
    for (int k = 1; k < 3; ++k)
      if ((v - mus[k]).norm() < (v - mus[best]).norm()) best = k;
    ASSERT_LT((v - mus[best]).norm(), 0.5) << "sample " << i << " far from every component";
    label[i] = best;
    ++counts[best];
    sums[best] += v;
  }
  int runs = 1;
  for (std::size_t i = 1; i < n; ++i) runs += label[i] != label[i - 1];
  EXPECT_EQ(runs, 3) << "samples are not grouped by component";
  for (int k = 0; k < 3; ++k) {
    const double se = std::sqrt(n * w[k] * (1 - w[k]));
    EXPECT_NEAR(static_cast<double>(counts[k]), n * w[k], 5.0 * se) << "component " << k;
    const double sd = std::sqrt((0.0004 + 0.0002 * k) * truncated_variance(2.5) / counts[k]);
    for (int d = 0; d < 4; ++d) EXPECT_NEAR(sums[k](d) / counts[k], mus[k](d), 5.0 * sd);
  }
}

TEST(Sample, ThreeDimensionalMarginal) {
  const sogmm::Gmm g = one_component();
  const std::size_t n = 100000;
  std::vector<float> x(3 * n);
  sogmm::sample(g, n, 3, 3, x.data());
  const Moments m = moments(x, 3);
  const Eigen::Matrix4d e = truncated_variance(2.5) * cov_of(g, 0);
  const Eigen::Vector4d mu = mean_of(g, 0);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(m.mean(a), mu(a), 5.0 * std::sqrt(e(a, a) / n));
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(m.cov(a, b), e(a, b), 6.0 * std::sqrt((e(a, a) * e(b, b) + e(a, b) * e(a, b)) / n));
  }
}

TEST(Sample, SeedDeterminesSamples) {
  const sogmm::Gmm g = one_component();
  const std::size_t n = 1000;
  std::vector<float> a(4 * n), b(4 * n), c(4 * n);
  sogmm::sample(g, n, 77, 4, a.data());
  sogmm::sample(g, n, 77, 4, b.data());
  sogmm::sample(g, n, 78, 4, c.data());
  EXPECT_EQ(0, std::memcmp(a.data(), b.data(), a.size() * sizeof(float)));
  EXPECT_NE(0, std::memcmp(a.data(), c.data(), a.size() * sizeof(float)));
}
