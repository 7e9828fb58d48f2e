// EM: agreement with scikit-learn's GaussianMixture from the same one-hot
// initialisation, recovery of a known mixture, determinism, validity.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "sogmm/em.hpp"
#include "sogmm/error.hpp"
#include "sogmm/fit.hpp"
#include "sogmm/kmeanspp.hpp"
#include "test_util.hpp"

using sogmm_test::cov_of;
using sogmm_test::mean_of;

namespace {

struct SklearnCase {
  std::vector<float> points;
  std::vector<std::size_t> seeds;
  nlohmann::json ref;
  sogmm::PointsView view() const { return {points.data(), points.size() / 4}; }
};

SklearnCase load_case(const std::string& name) {
  SklearnCase c;
  c.ref = sogmm_test::load_fixture(name);
  for (const auto& row : c.ref.at("points"))
    for (const auto& v : row) c.points.push_back(static_cast<float>(v.get<double>()));
  for (const auto& s : c.ref.at("seed_indices")) c.seeds.push_back(s.get<std::size_t>());
  return c;
}

// Compares a fitted model with sklearn's, component k against component k
// (component k started from seed k). Tolerances (relative 1e-3):
//   weights: |w - w_ref| <= 1e-3 w_ref;
//   means: |mu_d - ref_d| <= 1e-3 max(|ref_d|, sqrt(ref cov_dd)) (the component's own scale);
//   covariances: |c_ij - ref_ij| <= 1e-3 sqrt(ref_ii ref_jj) (scale of the entry).
void compare_with_sklearn(const sogmm::Gmm& g, const nlohmann::json& ref) {
  const auto& w = ref.at("weights");
  ASSERT_EQ(g.size(), w.size());
  for (std::size_t k = 0; k < g.size(); ++k) {
    const double wr = w[k].get<double>();
    EXPECT_NEAR(g.weights[k], wr, 1e-3 * wr) << "weight " << k;
    const auto& mr = ref.at("means")[k];
    const auto& cr = ref.at("covariances")[k];
    for (int d = 0; d < 4; ++d) {
      const double ref_d = mr[d].get<double>();
      const double scale = std::max(std::fabs(ref_d), std::sqrt(cr[d][d].get<double>()));
      EXPECT_NEAR(g.means[4 * k + d], ref_d, 1e-3 * scale) << "mean " << k << "," << d;
    }
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const double scale = std::sqrt(cr[i][i].get<double>() * cr[j][j].get<double>());
        EXPECT_NEAR(g.covariances[16 * k + 4 * i + j], cr[i][j].get<double>(), 1e-3 * scale)
            << "covariance " << k << " (" << i << "," << j << ")";
      }
  }
}

sogmm::EmOptions sklearn_options(const nlohmann::json& ref, int threads) {
  sogmm::EmOptions o;
  o.tol = ref.at("options").at("tol").get<double>();
  o.reg_covar = ref.at("options").at("reg_covar").get<double>();
  o.max_iter = ref.at("options").at("max_iter").get<int>();
  o.threads = threads;
  return o;
}

void run_sklearn_case(const std::string& name) {
  const SklearnCase c = load_case(name);
  for (int threads : {1, 2}) {
    SCOPED_TRACE("threads = " + std::to_string(threads));
    sogmm::EmReport report;
    const sogmm::Gmm g = sogmm::fit_em(c.view(), c.seeds, sklearn_options(c.ref, threads), &report);
    EXPECT_TRUE(sogmm_test::model_is_valid(g));
    compare_with_sklearn(g, c.ref);
    EXPECT_NEAR(report.log_likelihood, c.ref.at("lower_bound").get<double>(), 1e-4);
    EXPECT_EQ(report.iterations, c.ref.at("n_iter").get<int>());
    EXPECT_EQ(report.converged, c.ref.at("converged").get<bool>());
  }
}

}  // namespace

TEST(EmVsSklearn, SeparatedOneSeedPerCluster) { run_sklearn_case("em_sklearn_separated.json"); }

TEST(EmVsSklearn, OverlappingSixRandomSeeds) { run_sklearn_case("em_sklearn_overlap.json"); }

TEST(EmVsSklearn, LogLikelihoodPerIteration) {
  // With max_iter = k the report holds the mean log-likelihood of E-step k,
  // sklearn's lower_bounds_[k-1]. (Iteration 1 uses covariances of 1e-6 I and
  // sklearn's unnormalised initial weights 1/N, values of order -3e4, checked
  // relatively.)
  const SklearnCase c = load_case("em_sklearn_overlap.json");
  const auto& lbs = c.ref.at("lower_bounds");
  for (int k : {1, 2, 3, 6}) {
    sogmm::EmOptions o = sklearn_options(c.ref, 0);
    o.max_iter = k;
    sogmm::EmReport report;
    const sogmm::Gmm g = sogmm::fit_em(c.view(), c.seeds, o, &report);
    EXPECT_TRUE(sogmm_test::model_is_valid(g));
    const double e = lbs[k - 1].get<double>();
    EXPECT_NEAR(report.log_likelihood, e, k == 1 ? 1e-5 * std::fabs(e) : 1e-4) << "max_iter " << k;
    EXPECT_EQ(report.iterations, k);
    EXPECT_FALSE(report.converged) << "max_iter " << k;
  }
}

TEST(EmVsSklearn, FitEmFromInitialModelEqualsSeededStart) {
  // fit_em_from with the documented first model (means = seeds, cov = reg I,
  // equal weights 1/K) must agree with sklearn too: the weights' normalisation
  // only shifts the first iteration's log-likelihood, not the responsibilities.
  const SklearnCase c = load_case("em_sklearn_overlap.json");
  const std::size_t k = c.seeds.size();
  sogmm::Gmm init;
  init.resize(k);
  for (std::size_t m = 0; m < k; ++m) {
    init.weights[m] = 1.0f / k;
    for (int d = 0; d < 4; ++d) init.means[4 * m + d] = c.points[4 * c.seeds[m] + d];
    for (int i = 0; i < 16; ++i) init.covariances[16 * m + i] = (i % 5 == 0) ? 1e-6f : 0.0f;
  }
  sogmm::EmReport report;
  const sogmm::Gmm g = sogmm::fit_em_from(c.view(), init, sklearn_options(c.ref, 0), &report);
  compare_with_sklearn(g, c.ref);
  EXPECT_NEAR(report.log_likelihood, c.ref.at("lower_bound").get<double>(), 1e-4);
}

namespace {

struct KnownMixture {
  std::vector<Eigen::Vector4d> mus;
  std::vector<Eigen::Matrix4d> covs;
  std::vector<int> counts;
  std::vector<float> points;
  std::vector<int> labels;
};

KnownMixture known_mixture() {
  KnownMixture m;
  m.mus = {{0.0, 0.0, 1.0, 0.2}, {1.0, 0.2, 1.4, 0.8}, {-0.6, 0.9, 2.2, 0.5}};
  Eigen::Matrix4d a;
  a << 0.010, 0.003, 0.001, 0.000,  //
      0.003, 0.008, 0.000, 0.001,   //
      0.001, 0.000, 0.006, -0.001,  //
      0.000, 0.001, -0.001, 0.004;
  m.covs = {a, Eigen::Vector4d(0.012, 0.006, 0.004, 0.002).asDiagonal(), 0.5 * a + 0.002 * Eigen::Matrix4d::Identity()};
  m.counts = {1500, 900, 600};
  m.points = sogmm_test::draw_mixture(m.mus, m.covs, m.counts, 2024, &m.labels);
  return m;
}

// Matches each true component to the nearest fitted mean; checks the fitted
// parameters against the per-cluster sample statistics (what EM's MLE is for
// well-separated clusters) and the generating parameters.
void expect_recovers(const sogmm::Gmm& g, const KnownMixture& m) {
  ASSERT_EQ(g.size(), m.mus.size());
  const std::size_t n = m.labels.size();
  std::vector<bool> used(g.size(), false);
  for (std::size_t t = 0; t < m.mus.size(); ++t) {
    Eigen::Vector4d smean = Eigen::Vector4d::Zero();
    Eigen::Matrix4d scov = Eigen::Matrix4d::Zero();
    int cnt = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (m.labels[i] == static_cast<int>(t)) {
        smean += Eigen::Vector4d(m.points[4 * i], m.points[4 * i + 1], m.points[4 * i + 2], m.points[4 * i + 3]);
        ++cnt;
      }
    smean /= cnt;
    for (std::size_t i = 0; i < n; ++i)
      if (m.labels[i] == static_cast<int>(t)) {
        const Eigen::Vector4d d =
            Eigen::Vector4d(m.points[4 * i], m.points[4 * i + 1], m.points[4 * i + 2], m.points[4 * i + 3]) - smean;
        scov += d * d.transpose();
      }
    scov /= cnt;
    std::size_t best = 0;
    for (std::size_t k = 1; k < g.size(); ++k)
      if ((mean_of(g, k) - m.mus[t]).norm() < (mean_of(g, best) - m.mus[t]).norm()) best = k;
    ASSERT_FALSE(used[best]) << "two true components matched the same fitted one";
    used[best] = true;
    SCOPED_TRACE("true component " + std::to_string(t));
    EXPECT_NEAR(g.weights[best], static_cast<double>(cnt) / n, 2e-3);
    EXPECT_LT((mean_of(g, best) - smean).cwiseAbs().maxCoeff(), 2e-3);
    EXPECT_LT((cov_of(g, best) - scov).cwiseAbs().maxCoeff(), 2e-4);
    // Generating parameters: 5 standard errors.
    for (int d = 0; d < 4; ++d)
      EXPECT_NEAR(g.means[4 * best + d], m.mus[t](d), 5.0 * std::sqrt(m.covs[t](d, d) / cnt));
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        const Eigen::Matrix4d& c = m.covs[t];
        EXPECT_NEAR(cov_of(g, best)(i, j), c(i, j), 6.0 * std::sqrt((c(i, i) * c(j, j) + c(i, j) * c(i, j)) / cnt));
      }
  }
}

}  // namespace

TEST(Em, RecoversKnownSeparatedMixture) {
  const KnownMixture m = known_mixture();
  // Seeds: the first point of each true component (independent of k-means++).
  std::vector<std::size_t> seeds;
  for (int t = 0; t < 3; ++t)
    for (std::size_t i = 0; i < m.labels.size(); ++i)
      if (m.labels[i] == t) {
        seeds.push_back(i);
        break;
      }
  sogmm::EmReport report;
  const sogmm::Gmm g = sogmm::fit_em({m.points.data(), m.labels.size()}, seeds, sogmm::EmOptions{}, &report);
  EXPECT_TRUE(sogmm_test::model_is_valid(g));
  EXPECT_TRUE(report.converged);
  EXPECT_GE(report.iterations, 1);
  EXPECT_LE(report.iterations, 100);
  expect_recovers(g, m);
}

TEST(Em, FixedKFitRecoversKnownMixture) {
  const KnownMixture m = known_mixture();
  sogmm::FitOptions o;
  o.n_components = 3;
  o.seed = 5;
  const sogmm::FitResult r = sogmm::fit({m.points.data(), m.labels.size()}, o);
  EXPECT_EQ(r.n_points, m.labels.size());
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
  EXPECT_EQ(r.gmm.support_size, m.labels.size());
  expect_recovers(r.gmm, m);
}

TEST(Em, LogLikelihoodNonDecreasingAndStagesReported) {
  const KnownMixture m = known_mixture();
  sogmm::FitOptions o;
  o.bandwidth = 0.05;
  o.seed = 3;
  std::vector<double> lls;
  std::vector<sogmm::Stage> stages;
  const sogmm::FitResult r = sogmm::fit({m.points.data(), m.labels.size()}, o, [&](const sogmm::Progress& p) {
    stages.push_back(p.stage);
    // One value per iteration: heartbeats repeat the last step.
    if (p.stage == sogmm::Stage::Em && p.step == lls.size() + 1) lls.push_back(p.log_likelihood);
    return false;
  });
  EXPECT_TRUE(sogmm_test::model_is_valid(r.gmm));
  ASSERT_FALSE(stages.empty());
  EXPECT_EQ(stages.front(), sogmm::Stage::ModeCount);
  EXPECT_EQ(stages.back(), sogmm::Stage::Em);
  EXPECT_EQ(lls.size(), static_cast<std::size_t>(r.em.iterations)) << "one report per EM iteration";
  ASSERT_GE(lls.size(), 2u);
  for (std::size_t i = 2; i < lls.size(); ++i)  // EM never decreases the likelihood (up to reg_covar / float noise)
    EXPECT_GE(lls[i], lls[i - 1] - 1e-5) << "iteration " << i;
  EXPECT_EQ(lls.back(), r.em.log_likelihood) << "the report holds the last iteration's value";
  // Independent truth: the last E-step scored the model of the iteration
  // before; refit up to there and score that model in double.
  ASSERT_GE(r.em.iterations, 2);
  sogmm::FitOptions before = o;
  before.em.max_iter = r.em.iterations - 1;
  before.em.tol = 0.0;
  const sogmm::FitResult p = sogmm::fit({m.points.data(), m.labels.size()}, before);
  EXPECT_NEAR(r.em.log_likelihood, sogmm_test::score(p.gmm, m.points), 1e-5);
}

namespace {
// A "scene": 8 components of various shapes, 4000 points.
std::vector<float> scene_points() {
  std::vector<Eigen::Vector4d> mus;
  std::vector<Eigen::Matrix4d> covs;
  std::vector<int> counts;
  sogmm_test::TestRng r(99);
  for (int k = 0; k < 8; ++k) {
    mus.emplace_back(r.uniform() * 2 - 1, r.uniform() * 1.5 - 0.75, 1.0 + 1.5 * r.uniform(), r.uniform());
    Eigen::Matrix4d a;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) a(i, j) = 0.1 * r.normal();
    covs.push_back(a * a.transpose() * 0.3 + 0.0005 * Eigen::Matrix4d::Identity());
    counts.push_back(300 + 100 * (k % 4));
  }
  return sogmm_test::draw_mixture(mus, covs, counts, 7);
}
}  // namespace

TEST(Determinism, SameSeedBitIdenticalAcrossThreadsAndCalls) {
  const std::vector<float> pts = scene_points();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  sogmm::FitOptions o;
  o.bandwidth = 0.05;
  o.seed = 123;
  o.em.threads = 1;
  const sogmm::FitResult a = sogmm::fit(v, o);
  o.em.threads = 2;
  const sogmm::FitResult b = sogmm::fit(v, o);
  const sogmm::FitResult c = sogmm::fit(v, o);
  ASSERT_GT(a.gmm.size(), 1u);
  EXPECT_TRUE(sogmm_test::model_is_valid(a.gmm));
  EXPECT_TRUE(sogmm_test::bit_identical(a.gmm, b.gmm)) << "1 vs 2 threads differ";
  EXPECT_TRUE(sogmm_test::bit_identical(b.gmm, c.gmm)) << "two calls differ";
  EXPECT_EQ(a.em.log_likelihood, b.em.log_likelihood);
  EXPECT_EQ(a.em.iterations, b.em.iterations);
  // Different seeds: deterministic, so "usually differ" means at least one of three does.
  int differing = 0;
  for (std::uint64_t s : {1ull, 2ull, 3ull}) {
    o.seed = s;
    const sogmm::FitResult d = sogmm::fit(v, o);
    EXPECT_TRUE(sogmm_test::model_is_valid(d.gmm));
    EXPECT_EQ(d.gmm.size(), a.gmm.size()) << "M depends only on the mode count, not the seed";
    differing += !sogmm_test::bit_identical(a.gmm, d.gmm);
  }
  EXPECT_GE(differing, 1) << "seed has no effect";
}

// n_init runs: run r is exactly the single fit with seed + r, the kept one is
// the earliest with the highest final log-likelihood, and the choice does not
// depend on the thread count.
TEST(Runs, KeepTheBestOfSingleFitsWithConsecutiveSeeds) {
  const std::vector<float> pts = scene_points();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  sogmm::FitOptions o;
  o.n_components = 12;  // more components than clusters: optima differ by seed
  o.seed = 40;
  o.n_init = 4;
  o.em.threads = 2;
  std::vector<int> runs_reported;
  const sogmm::FitResult best = sogmm::fit(v, o, [&](const sogmm::Progress& p) {
    if (p.stage == sogmm::Stage::Run && p.step > 0) runs_reported.push_back(static_cast<int>(p.step));
    return false;
  });
  EXPECT_EQ(runs_reported, std::vector<int>({1, 2, 3, 4}));
  ASSERT_EQ(best.run_log_likelihoods.size(), 4u);
  EXPECT_TRUE(sogmm_test::model_is_valid(best.gmm));

  std::vector<sogmm::FitResult> singles;
  for (int r = 0; r < 4; ++r) {
    sogmm::FitOptions one = o;
    one.n_init = 1;
    one.seed = o.seed + r;
    singles.push_back(sogmm::fit(v, one));
    EXPECT_EQ(singles.back().run_log_likelihoods, std::vector<double>({singles.back().em.log_likelihood}));
    EXPECT_EQ(best.run_log_likelihoods[r], singles.back().em.log_likelihood) << "run " << r;
  }
  int expected = 0;
  for (int r = 1; r < 4; ++r)
    if (singles[r].em.log_likelihood > singles[expected].em.log_likelihood) expected = r;
  EXPECT_EQ(best.run, expected);
  EXPECT_TRUE(sogmm_test::bit_identical(best.gmm, singles[expected].gmm));
  EXPECT_EQ(best.em.iterations, singles[expected].em.iterations);
  // The seeds give different optima here, so keeping the best is not vacuous.
  const auto [lo, hi] = std::minmax_element(best.run_log_likelihoods.begin(), best.run_log_likelihoods.end());
  EXPECT_LT(*lo, *hi);
  EXPECT_EQ(best.em.log_likelihood, *hi);

  o.em.threads = 1;
  const sogmm::FitResult serial = sogmm::fit(v, o);
  EXPECT_EQ(serial.run, best.run);
  EXPECT_TRUE(sogmm_test::bit_identical(serial.gmm, best.gmm));
}

TEST(Runs, OutOfRangeRunCountIsRefused) {
  const std::vector<float> pts = scene_points();
  const sogmm::PointsView v{pts.data(), pts.size() / 4};
  for (int n : {0, -1, sogmm::kMaxRuns + 1}) {
    sogmm::FitOptions o;
    o.n_init = n;
    try {
      sogmm::fit(v, o);
      ADD_FAILURE() << "n_init " << n << " accepted";
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument);
      EXPECT_NE(std::string(e.what()).find("n_init"), std::string::npos) << e.what();
    }
  }
}

TEST(Determinism, FitEmThreadsBitIdentical) {
  const SklearnCase c = load_case("em_sklearn_overlap.json");
  sogmm::EmOptions o = sklearn_options(c.ref, 1);
  const sogmm::Gmm a = sogmm::fit_em(c.view(), c.seeds, o);
  o.threads = 2;
  const sogmm::Gmm b = sogmm::fit_em(c.view(), c.seeds, o);
  o.threads = 0;
  const sogmm::Gmm d = sogmm::fit_em(c.view(), c.seeds, o);
  EXPECT_TRUE(sogmm_test::bit_identical(a, b));
  EXPECT_TRUE(sogmm_test::bit_identical(a, d));
}

TEST(KMeansPP, DeterministicDistinctAndSpread) {
  const KnownMixture m = known_mixture();
  const sogmm::PointsView v{m.points.data(), m.labels.size()};
  const auto a = sogmm::kmeanspp_seeds(v, 3, 11), b = sogmm::kmeanspp_seeds(v, 3, 11);
  EXPECT_EQ(a, b);
  ASSERT_EQ(a.size(), 3u);
  std::vector<int> hit(3, 0);
  for (std::size_t i : a) {
    ASSERT_LT(i, v.size);
    ++hit[m.labels[i]];
  }
  // Clusters ~10 sigma apart: greedy k-means++ puts one seed in each.
  EXPECT_EQ(hit, std::vector<int>({1, 1, 1}));
  // K = N: every point exactly once.
  const std::vector<float> small = {0, 0, 1, 0, 1, 0, 1, 0.5f, 0, 1, 1, 1, 2, 2, 2, 0.2f};
  auto all = sogmm::kmeanspp_seeds({small.data(), 4}, 4, 1);
  std::sort(all.begin(), all.end());
  EXPECT_EQ(all, std::vector<std::size_t>({0, 1, 2, 3}));
}
