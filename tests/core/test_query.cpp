// score_samples and regress_gray (issue 17): the vectorised exact queries
// against an independent long-double reference on random models (fixed
// seeds; more than one kernel chunk of components, a partial last block),
// bitwise identity for any thread count, and the culled queries within their
// documented bound (a hand-computed case and random models).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "sogmm/inference.hpp"
#include "test_util.hpp"

using sogmm_test::cov_of;
using sogmm_test::mean_of;
using sogmm_test::set_component;

namespace {

using LD = long double;
using VecL = Eigen::Matrix<LD, Eigen::Dynamic, 1>;
using MatL = Eigen::Matrix<LD, Eigen::Dynamic, Eigen::Dynamic>;
const LD kLog2PiL = std::log(2.0L * 3.14159265358979323846264338327950288L);

MatL cov_l(const sogmm::Gmm& g, std::size_t k, int d) { return cov_of(g, k).topLeftCorner(d, d).cast<LD>(); }
VecL mean_l(const sogmm::Gmm& g, std::size_t k, int d) { return mean_of(g, k).head(d).cast<LD>(); }

// log N(x | mu, S) in long double by the textbook formula.
LD log_normal(const VecL& x, const VecL& mu, const MatL& s) {
  const Eigen::LLT<MatL> llt(s);
  const VecL d = x - mu;
  const LD logdet = 2 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
  return -0.5L * (static_cast<LD>(x.size()) * kLog2PiL + logdet + d.dot(llt.solve(d)));
}

LD log_sum_exp(const std::vector<LD>& t) {
  LD mx = t[0];
  for (LD v : t) mx = std::max(mx, v);
  LD s = 0;
  for (LD v : t) s += std::exp(v - mx);
  return mx + std::log(s);
}

LD ref_score(const sogmm::Gmm& g, const float* x, int d) {
  VecL p(d);
  for (int i = 0; i < d; ++i) p[i] = x[i];
  std::vector<LD> t;
  for (std::size_t k = 0; k < g.size(); ++k)
    t.push_back(std::log(static_cast<LD>(g.weights[k])) + log_normal(p, mean_l(g, k, d), cov_l(g, k, d)));
  return log_sum_exp(t);
}

// The documented regression (sogmm/inference.hpp): per-component
// conditionals plus the background of weight 1e-6 with 100 x the total
// spatial covariance and the prior gray. Returns mean and variance; `range`
// receives max - min of the conditional means at x.
std::pair<LD, LD> ref_regress(const sogmm::Gmm& g, const float* x, LD* range = nullptr) {
  const std::size_t m = g.size();
  VecL p(3);
  for (int i = 0; i < 3; ++i) p[i] = x[i];
  LD w = 0;
  VecL mu = VecL::Zero(4);
  for (std::size_t k = 0; k < m; ++k) {
    w += g.weights[k];
    mu += static_cast<LD>(g.weights[k]) * mean_l(g, k, 4);
  }
  mu /= w;
  MatL tot = MatL::Zero(4, 4);
  for (std::size_t k = 0; k < m; ++k) {
    const VecL d = mean_l(g, k, 4) - mu;
    tot += static_cast<LD>(g.weights[k]) * (cov_l(g, k, 4) + d * d.transpose());
  }
  tot /= w;
  std::vector<LD> lw, lambda, nu2;
  for (std::size_t k = 0; k < m; ++k) {
    const MatL c = cov_l(g, k, 4);
    const VecL gain = c.topLeftCorner(3, 3).llt().solve(VecL(c.topRightCorner(3, 1)));
    lw.push_back(std::log(static_cast<LD>(g.weights[k])) + log_normal(p, mean_l(g, k, 3), c.topLeftCorner(3, 3)));
    lambda.push_back(g.means[4 * k + 3] + gain.dot(p - mean_l(g, k, 3)));
    nu2.push_back(std::max<LD>(0, c(3, 3) - gain.dot(VecL(c.topRightCorner(3, 1)))));
  }
  lw.push_back(std::log(1e-6L * w) + log_normal(p, mu.head(3), 100 * tot.topLeftCorner(3, 3)));
  lambda.push_back(mu[3]);
  nu2.push_back(tot(3, 3));
  const LD lse = log_sum_exp(lw);
  LD mean = 0;
  for (std::size_t k = 0; k <= m; ++k) mean += std::exp(lw[k] - lse) * lambda[k];
  LD var = 0;
  for (std::size_t k = 0; k <= m; ++k)
    var += std::exp(lw[k] - lse) * (nu2[k] + (lambda[k] - mean) * (lambda[k] - mean));
  if (range) *range = *std::max_element(lambda.begin(), lambda.end()) - *std::min_element(lambda.begin(), lambda.end());
  return {mean, var};
}

// M surface-like components in a box of side `side` m: covariances B B^T +
// 1e-5 I with B random of scale 2-5 cm (gray entries included, so the
// regression has gains).
sogmm::Gmm random_model(std::size_t m, std::uint64_t seed, double side = 2.0) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sogmm::Gmm g;
  g.resize(m);
  std::vector<double> w(m);
  double total = 0;
  for (std::size_t k = 0; k < m; ++k) total += (w[k] = 0.1 + u(rng));
  for (std::size_t k = 0; k < m; ++k) {
    Eigen::Matrix4d b;
    for (int i = 0; i < 16; ++i) b(i / 4, i % 4) = (u(rng) - 0.5) * (0.02 + 0.03 * u(rng));
    const Eigen::Matrix4d c = b * b.transpose() + 1e-5 * Eigen::Matrix4d::Identity();
    set_component(g, k, w[k] / total, Eigen::Vector4d(side * u(rng), side * u(rng), 1 + side * u(rng), u(rng)), c);
  }
  g.support_size = 1000;
  return g;
}

// n points near components' means (within 2.5 cm per coordinate, which can
// be far in a thin component's terms), every tenth up to 50 cm off.
std::vector<float> random_points(const sogmm::Gmm& g, std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<float> pts(4 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(u(rng) * static_cast<double>(g.size())) % g.size();
    const double spread = i % 10 == 0 ? 1.0 : 0.05;
    for (int j = 0; j < 4; ++j) pts[4 * i + j] = static_cast<float>(g.means[4 * k + j] + spread * (u(rng) - 0.5));
  }
  return pts;
}

std::vector<float> xyz_of(const std::vector<float>& pts) {
  std::vector<float> xyz(pts.size() / 4 * 3);
  for (std::size_t i = 0; i < pts.size() / 4; ++i)
    for (int j = 0; j < 3; ++j) xyz[3 * i + j] = pts[4 * i + j];
  return xyz;
}

std::vector<float> rows_of(const std::vector<float>& pts, int d) { return d == 4 ? pts : xyz_of(pts); }

}  // namespace

// Exact mode: the kernels work in double like the reference, only the order
// of operations and exp (relative error < 4e-16) differ, so the score agrees
// to about 1e-14 relative; 1e-12 leaves room for the far points' large
// Mahalanobis terms. The regression is returned in float: within 2.5e-7
// relative (two float roundings).
TEST(QueryExact, MatchesLongDoubleReference) {
  for (std::uint64_t seed : {1u, 2u}) {
    const sogmm::Gmm g = random_model(300, seed);  // 3 chunks of 128 components
    const std::size_t n = 150;                     // 2 full blocks of 64 and a partial one
    const std::vector<float> pts = random_points(g, n, seed + 10);
    for (int d : {3, 4}) {
      const std::vector<float> rows = rows_of(pts, d);
      std::vector<double> s(n);
      sogmm::score_samples(g, rows.data(), n, d, s.data());
      for (std::size_t i = 0; i < n; ++i) {
        const double ref = static_cast<double>(ref_score(g, &rows[d * i], d));
        EXPECT_NEAR(s[i], ref, 1e-12 * std::max(1.0, std::fabs(ref))) << "seed " << seed << " dims " << d << " point " << i;
      }
    }
    const std::vector<float> xyz = xyz_of(pts);
    std::vector<float> mean(n), var(n);
    sogmm::regress_gray(g, xyz.data(), n, mean.data(), var.data());
    for (std::size_t i = 0; i < n; ++i) {
      const auto [rm, rv] = ref_regress(g, &xyz[3 * i]);
      EXPECT_NEAR(mean[i], static_cast<double>(rm), 2.5e-7 * std::max(1.0L, std::fabs(rm))) << "point " << i;
      EXPECT_NEAR(var[i], static_cast<double>(rv), 2.5e-7 * static_cast<double>(rv)) << "point " << i;
    }
  }
}

// Every point is computed by one thread from the same list in the same
// order, so any team gives the same bits, exact or culled.
TEST(QueryThreads, BitwiseIdenticalForAnyTeam) {
  const sogmm::Gmm g = random_model(200, 3);
  const std::size_t n = 1000;
  const std::vector<float> pts = random_points(g, n, 4);
  const std::vector<float> xyz = xyz_of(pts);
  for (double nats : {0.0, 10.0}) {
    std::vector<double> s4_1(n), s3_1(n);
    std::vector<float> m_1(n), v_1(n);
    for (int threads : {1, 2, 3}) {
      sogmm::QueryOptions o;
      o.threads = threads;
      o.truncation_nats = nats;
      std::vector<double> s4(n), s3(n);
      std::vector<float> mean(n), var(n);
      sogmm::score_samples(g, pts.data(), n, 4, s4.data(), o);
      sogmm::score_samples(g, xyz.data(), n, 3, s3.data(), o);
      sogmm::regress_gray(g, xyz.data(), n, mean.data(), var.data(), o);
      if (threads == 1) {
        s4_1 = s4, s3_1 = s3, m_1 = mean, v_1 = var;
        continue;
      }
      EXPECT_EQ(0, std::memcmp(s4.data(), s4_1.data(), n * sizeof(double))) << threads << " threads, nats " << nats;
      EXPECT_EQ(0, std::memcmp(s3.data(), s3_1.data(), n * sizeof(double))) << threads << " threads, nats " << nats;
      EXPECT_EQ(0, std::memcmp(mean.data(), m_1.data(), n * sizeof(float))) << threads << " threads, nats " << nats;
      EXPECT_EQ(0, std::memcmp(var.data(), v_1.data(), n * sizeof(float))) << threads << " threads, nats " << nats;
    }
  }
}

// Two unit-covariance components 7 apart, a point on the first: the second's
// term is exp(-24.5) of the first's. Culled at 10 nats it is provably
// negligible (the index radius is sqrt(2 (10 + 0 + 8)) = 6 < 7 sigma, and
// its constant is no larger), so the culled score is the first term alone;
// the exact one adds log1p(exp(-24.5)) = 2.3e-11, resolvable in double.
TEST(QueryCulled, SkipsAProvablyNegligibleComponentHandComputed) {
  sogmm::Gmm g;
  g.resize(2);
  set_component(g, 0, 0.5, Eigen::Vector4d(0, 0, 0, 0.5), Eigen::Matrix4d::Identity());
  set_component(g, 1, 0.5, Eigen::Vector4d(7, 0, 0, 0.5), Eigen::Matrix4d::Identity());
  const float x[4] = {0, 0, 0, 0.5f};
  const double first = std::log(0.5) - 2.0 * std::log(2.0 * M_PI);
  double exact = 0, culled = 0;
  sogmm::score_samples(g, x, 1, 4, &exact);
  sogmm::QueryOptions o;
  o.truncation_nats = 10;
  sogmm::score_samples(g, x, 1, 4, &culled, o);
  EXPECT_NEAR(exact, first + std::log1p(std::exp(-24.5)), 1e-15);
  EXPECT_NEAR(culled, first, 1e-15);
  EXPECT_GT(exact - culled, 2e-11);
  // At 30 nats the second component is no longer provably negligible.
  o.truncation_nats = 30;
  sogmm::score_samples(g, x, 1, 4, &culled, o);
  EXPECT_EQ(culled, exact);
}

// Random models: the culled score never exceeds the exact one (it sums a
// subset of the terms) and falls short by at most log(1 + M exp(-nats)); the
// culled regression moves by at most the skipped weight share (< M
// exp(-nats)) times the range of the conditional means. Small cutoffs make
// the culling, and so the bound, bite. The points are drawn from the model,
// as a frame's points lie on its surfaces (one badly explained point lowers
// its whole block's cut, so culling then skips little there), and the
// components crowd a 60 cm box, so that skipped terms are large enough to
// show in double.
TEST(QueryCulled, WithinTheDocumentedBound) {
  for (std::uint64_t seed : {5u, 6u, 7u}) {
    const std::size_t m = 250, n = 1000;
    const sogmm::Gmm g = random_model(m, seed, 0.6);
    std::vector<float> pts(4 * n);
    sogmm::sample(g, n, seed + 20, 4, pts.data());
    const std::vector<float> xyz = xyz_of(pts);
    std::vector<double> exact(n), culled(n);
    std::vector<float> em(n), ev(n), cm(n), cv(n);
    sogmm::score_samples(g, pts.data(), n, 4, exact.data());
    sogmm::regress_gray(g, xyz.data(), n, em.data(), ev.data());
    std::vector<LD> range(n);
    for (std::size_t i = 0; i < n; ++i) ref_regress(g, &xyz[3 * i], &range[i]);
    for (double nats : {2.0, 6.0, 20.0}) {
      sogmm::QueryOptions o;
      o.truncation_nats = nats;
      sogmm::score_samples(g, pts.data(), n, 4, culled.data(), o);
      sogmm::regress_gray(g, xyz.data(), n, cm.data(), cv.data(), o);
      const double bound = std::log1p(static_cast<double>(m) * std::exp(-nats));
      int differ = 0;
      for (std::size_t i = 0; i < n; ++i) {
        const double slack = 1e-13 * std::max(1.0, std::fabs(exact[i]));
        EXPECT_LE(culled[i], exact[i] + slack) << "seed " << seed << " nats " << nats << " point " << i;
        EXPECT_LE(exact[i] - culled[i], bound + slack) << "seed " << seed << " nats " << nats << " point " << i;
        differ += culled[i] != exact[i];
        const double share = static_cast<double>(m) * std::exp(-nats);
        EXPECT_LE(std::fabs(cm[i] - em[i]), share * static_cast<double>(range[i]) + 2.5e-7 * std::max(1.0f, std::fabs(em[i])))
            << "seed " << seed << " nats " << nats << " point " << i;
      }
      if (nats == 2.0) {
        EXPECT_GT(differ, 0) << "culling skipped nothing at 2 nats";
      }
    }
  }
}

TEST(QueryOptionsTest, RejectsBadTruncation) {
  const sogmm::Gmm g = random_model(3, 1);
  const float x[4] = {0, 0, 0, 0};
  double s = 0;
  float mean = 0;
  for (double bad : {-1.0, std::nan(""), static_cast<double>(INFINITY)}) {
    sogmm::QueryOptions o;
    o.truncation_nats = bad;
    sogmm_test::expect_error([&] { sogmm::score_samples(g, x, 1, 4, &s, o); }, sogmm::ErrorCode::InvalidArgument,
                             {"truncation_nats"}, "score");
    sogmm_test::expect_error([&] { sogmm::regress_gray(g, x, 1, &mean, nullptr, o); },
                             sogmm::ErrorCode::InvalidArgument, {"truncation_nats"}, "regress");
  }
}
