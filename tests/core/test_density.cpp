// score_samples / mean_log_likelihood against closed forms, and gray regression
// against a hand-computed two-component example.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "sogmm/inference.hpp"
#include "test_util.hpp"

using sogmm_test::cov_of;
using sogmm_test::mean_of;
using sogmm_test::set_component;

namespace {

constexpr double kLog2Pi = 1.8378770664093454836;

// log N(x | mu, S) in double, from the textbook formula via Eigen's LDLT.
double log_normal(const Eigen::VectorXd& x, const Eigen::VectorXd& mu, const Eigen::MatrixXd& s) {
  const Eigen::LLT<Eigen::MatrixXd> llt(s);
  const Eigen::VectorXd d = x - mu;
  const double maha = d.dot(llt.solve(d));
  const double logdet = 2.0 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
  return -0.5 * (static_cast<double>(x.size()) * kLog2Pi + logdet + maha);
}

// log sum_k w_k N(x | mu_k, S_k) over the first `dims` coordinates (marginal).
double log_mixture(const sogmm::Gmm& g, const Eigen::VectorXd& x, int dims) {
  std::vector<double> terms;
  for (std::size_t k = 0; k < g.size(); ++k) {
    const Eigen::VectorXd mu = mean_of(g, k).head(dims);
    const Eigen::MatrixXd s = cov_of(g, k).topLeftCorner(dims, dims);
    terms.push_back(std::log(static_cast<double>(g.weights[k])) + log_normal(x, mu, s));
  }
  double mx = terms[0];
  for (double t : terms) mx = std::max(mx, t);
  double sum = 0.0;
  for (double t : terms) sum += std::exp(t - mx);
  return mx + std::log(sum);
}

sogmm::Gmm three_component_model() {
  sogmm::Gmm g;
  g.resize(3);
  Eigen::Matrix4d a;
  a << 0.04, 0.01, -0.005, 0.002,  //
      0.01, 0.03, 0.004, -0.003,   //
      -0.005, 0.004, 0.05, 0.001,  //
      0.002, -0.003, 0.001, 0.01;
  Eigen::Matrix4d b = Eigen::Vector4d(0.02, 0.01, 0.03, 0.04).asDiagonal();
  Eigen::Matrix4d c;
  c << 0.09, -0.02, 0.0, 0.01,  //
      -0.02, 0.05, 0.01, 0.0,   //
      0.0, 0.01, 0.02, -0.004,  //
      0.01, 0.0, -0.004, 0.02;
  set_component(g, 0, 0.2, Eigen::Vector4d(0.1, -0.2, 1.2, 0.3), a);
  set_component(g, 1, 0.5, Eigen::Vector4d(0.6, 0.1, 1.8, 0.7), b);
  set_component(g, 2, 0.3, Eigen::Vector4d(-0.4, 0.3, 2.1, 0.5), c);
  g.support_size = 1000;
  return g;
}

}  // namespace

TEST(ScoreSamples, StandardNormalHandComputed) {
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector4d::Zero(), Eigen::Matrix4d::Identity());
  const float x4[8] = {0, 0, 0, 0, 1, 0, 0, 0};
  double out[2];
  sogmm::score_samples(g, x4, 2, 4, out);
  EXPECT_NEAR(out[0], -3.6757541328186907, 1e-9);            // -2 log(2 pi)
  EXPECT_NEAR(out[1], -3.6757541328186907 - 0.5, 1e-9);      // one unit away
  const float x3[6] = {0, 0, 0, 0, 2, 0};
  sogmm::score_samples(g, x3, 2, 3, out);
  EXPECT_NEAR(out[0], -2.7568155996140180, 1e-9);            // -1.5 log(2 pi)
  EXPECT_NEAR(out[1], -2.7568155996140180 - 2.0, 1e-9);
}

TEST(ScoreSamples, DiagonalHandComputed) {
  // One component, Sigma = diag(4, 1, 0.25, 1): log det = log 4 + log 0.25 = 0.
  sogmm::Gmm g;
  g.resize(1);
  set_component(g, 0, 1.0, Eigen::Vector4d(1, 2, 3, 0.5),
                Eigen::Vector4d(4, 1, 0.25, 1).asDiagonal().toDenseMatrix());
  const float x[4] = {3, 2, 3.5, 0.5};  // Mahalanobis^2 = 4/4 + 0.25/0.25 = 2
  double out;
  sogmm::score_samples(g, x, 1, 4, &out);
  EXPECT_NEAR(out, -2.0 * kLog2Pi - 1.0, 1e-9);
  const float x3[3] = {3, 2, 3.5};
  sogmm::score_samples(g, x3, 1, 3, &out);  // marginal: diag(4, 1, 0.25), log det = 0
  EXPECT_NEAR(out, -1.5 * kLog2Pi - 1.0, 1e-9);
}

TEST(ScoreSamples, JointAndMarginalMatchClosedFormMixture) {
  const sogmm::Gmm g = three_component_model();
  sogmm_test::TestRng rng(11);
  const std::size_t n = 200;
  std::vector<float> x4(4 * n), x3(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = i % 3;
    for (int d = 0; d < 4; ++d) {
      x4[4 * i + d] = static_cast<float>(g.means[4 * k + d] + 0.4 * rng.normal());
      if (d < 3) x3[3 * i + d] = x4[4 * i + d];
    }
  }
  std::vector<double> s4(n), s3(n);
  sogmm::score_samples(g, x4.data(), n, 4, s4.data());
  sogmm::score_samples(g, x3.data(), n, 3, s3.data());
  double mean4 = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::VectorXd p4(4), p3(3);
    for (int d = 0; d < 4; ++d) p4(d) = x4[4 * i + d];
    for (int d = 0; d < 3; ++d) p3(d) = x3[3 * i + d];
    const double e4 = log_mixture(g, p4, 4), e3 = log_mixture(g, p3, 3);
    EXPECT_NEAR(s4[i], e4, 1e-6 * std::max(1.0, std::fabs(e4))) << "point " << i;
    EXPECT_NEAR(s3[i], e3, 1e-6 * std::max(1.0, std::fabs(e3))) << "point " << i;
    mean4 += e4 / n;
  }
  EXPECT_NEAR(sogmm::mean_log_likelihood(g, x4.data(), n, 4), mean4, 1e-6 * std::max(1.0, std::fabs(mean4)));
}

TEST(ScoreSamples, FarPointStaysFiniteInLogDomain) {
  // 100 m from a component of 1 cm: the density underflows in linear space
  // (log ~ -5e7) but the log-density must be finite and exact.
  const sogmm::Gmm g = three_component_model();
  sogmm::Gmm tight;
  tight.resize(1);
  set_component(tight, 0, 1.0, Eigen::Vector4d(0, 0, 1, 0.5), 1e-4 * Eigen::Matrix4d::Identity());
  const float x[4] = {100, 0, 1, 0.5};
  double out;
  sogmm::score_samples(tight, x, 1, 4, &out);
  Eigen::VectorXd p(4);
  p << 100, 0, 1, 0.5;
  const double e = log_mixture(tight, p, 4);
  ASSERT_TRUE(std::isfinite(out)) << out;
  EXPECT_NEAR(out, e, 1e-6 * std::fabs(e));
  const float y[4] = {50, -30, 10, 0.0};
  sogmm::score_samples(g, y, 1, 4, &out);
  p << 50, -30, 10, 0.0;
  ASSERT_TRUE(std::isfinite(out));
  EXPECT_NEAR(out, log_mixture(g, p, 4), 1e-6 * std::fabs(out));
}

// ---------------------------------------------------------------------------
// Gray regression. Two components with Sigma_xx = I:
//   c1: pi, mu = (0,0,0, 0.2), Sigma_gx = (0.1, 0, 0), Sigma_gg = 0.05 -> nu^2 = 0.04
//   c2: pi, mu = (1,0,0, 0.8), Sigma_gx = (0, 0.2, 0), Sigma_gg = 0.09 -> nu^2 = 0.05
namespace {
sogmm::Gmm regression_model(double pi1, double pi2) {
  sogmm::Gmm g;
  g.resize(2);
  Eigen::Matrix4d c1 = Eigen::Matrix4d::Identity(), c2 = Eigen::Matrix4d::Identity();
  c1(3, 3) = 0.05;
  c1(3, 0) = c1(0, 3) = 0.1;
  c2(3, 3) = 0.09;
  c2(3, 1) = c2(1, 3) = 0.2;
  set_component(g, 0, pi1, Eigen::Vector4d(0, 0, 0, 0.2), c1);
  set_component(g, 1, pi2, Eigen::Vector4d(1, 0, 0, 0.8), c2);
  return g;
}
}  // namespace

TEST(RegressGray, HandComputedTwoComponents) {
  const sogmm::Gmm g = regression_model(0.5, 0.5);
  // (0.5, 0.5, 0): equidistant, w = (1/2, 1/2); lambda1 = 0.2 + 0.1*0.5 = 0.25,
  // lambda2 = 0.8 + 0.2*0.5 = 0.9; mean = 0.575;
  // variance = 0.5 (0.04 + 0.0625) + 0.5 (0.05 + 0.81) - 0.575^2 = 0.150625.
  // (0, 0, 0): w1 = 1 / (1 + e^-0.5), lambda = (0.2, 0.8).
  const float xyz[6] = {0.5f, 0.5f, 0.0f, 0.0f, 0.0f, 0.0f};
  float mean[2], var[2];
  sogmm::regress_gray(g, xyz, 2, mean, var);
  EXPECT_NEAR(mean[0], 0.575, 1e-6);
  EXPECT_NEAR(var[0], 0.150625, 1e-6);
  const double w1 = 1.0 / (1.0 + std::exp(-0.5)), w2 = 1.0 - w1;
  const double m = 0.2 * w1 + 0.8 * w2;
  EXPECT_NEAR(mean[1], m, 1e-6);
  EXPECT_NEAR(var[1], w1 * (0.04 + 0.04) + w2 * (0.05 + 0.64) - m * m, 1e-6);
  // Variance pointer may be null.
  float only_mean;
  sogmm::regress_gray(g, xyz, 1, &only_mean, nullptr);
  EXPECT_NEAR(only_mean, 0.575, 1e-6);
}

TEST(RegressGray, MixingWeightsEnter) {
  const sogmm::Gmm g = regression_model(0.3, 0.7);
  const float xyz[3] = {0.5f, 0.5f, 0.0f};  // equidistant: w = (0.3, 0.7)
  float mean, var;
  sogmm::regress_gray(g, xyz, 1, &mean, &var);
  const double m = 0.3 * 0.25 + 0.7 * 0.9;
  EXPECT_NEAR(mean, m, 1e-6);
  EXPECT_NEAR(var, 0.3 * (0.04 + 0.0625) + 0.7 * (0.05 + 0.81) - m * m, 1e-6);
}

TEST(RegressGray, FarPointTakesThePriorNotZero) {
  // 100 m along x: log-weights -5000 and -4900.5 for the components, about -50
  // for the background (issue 14 item 4), so the answer is the prior: gray
  // 0.5 (0.2 + 0.8) / 1 = 0.5, variance 0.5 (0.05 + 0.09) + 0.5 (0.09 + 0.09)
  // = 0.16 (the nearest component's line would give 0.8 + 0.2 y; the
  // authors' code returns 0 here).
  const sogmm::Gmm g = regression_model(0.5, 0.5);
  const float xyz[3] = {100.0f, 0.0f, 0.0f};
  float mean, var;
  sogmm::regress_gray(g, xyz, 1, &mean, &var);
  EXPECT_NEAR(mean, 0.5, 1e-6);
  EXPECT_NEAR(var, 0.16, 1e-6);
}

TEST(RegressGray, SingleComponentIsLinearRegression) {
  // One general component: mean = mu_g + S_gx S_xx^-1 (x - mu_x) exactly (closed
  // form in Eigen), variance = S_gg - S_gx S_xx^-1 S_xg at every point.
  sogmm::Gmm g = three_component_model();
  sogmm::Gmm one;
  one.resize(1);
  set_component(one, 0, 1.0, mean_of(g, 0), cov_of(g, 0));
  const Eigen::Matrix4d c = cov_of(one, 0);
  const Eigen::Vector4d mu = mean_of(one, 0);
  const Eigen::Matrix3d sxx = c.topLeftCorner<3, 3>();
  const Eigen::RowVector3d sgx = c.block<1, 3>(3, 0);
  const double nu2 = c(3, 3) - sgx * sxx.ldlt().solve(sgx.transpose());
  const float xyz[9] = {0.1f, -0.2f, 1.2f, 0.3f, 0.0f, 1.0f, -0.2f, -0.5f, 1.5f};
  float mean[3], var[3];
  sogmm::regress_gray(one, xyz, 3, mean, var);
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d x(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    const double e = mu(3) + sgx * sxx.ldlt().solve(x - mu.head<3>());
    EXPECT_NEAR(mean[i], e, 1e-5) << i;
    EXPECT_NEAR(var[i], nu2, 1e-6) << i;
  }
}
