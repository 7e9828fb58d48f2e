// EmOptions::tol_standard_errors: EM also stops when a pass gains less than c
// standard errors of the mean log-likelihood (issue 35's convergence test
// from the data's own noise). Checked against the per-point scores computed
// independently in double (score_samples) and against the stopping rule
// applied by hand to a traced run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "sogmm/em.hpp"
#include "sogmm/error.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/kmeanspp.hpp"
#include "test_util.hpp"

namespace {

sogmm::PointsView view(const std::vector<float>& p) { return {p.data(), p.size() / 4}; }

// A room-like frame (8 planar patches, 4000 points; test_util.hpp) fitted
// with 8 components: the per-pass gains fall slowly through the thresholds.
constexpr std::size_t kK = 8;

sogmm::EmReport run(const std::vector<float>& pts, sogmm::EmOptions o, std::vector<double>* ll = nullptr) {
  sogmm::EmReport r;
  sogmm::fit_em(view(pts), sogmm::kmeanspp_seeds(view(pts), kK, 0), o, &r, [&](int, double v) {
    if (ll) ll->push_back(v);
  });
  return r;
}

}  // namespace

// The standard error the E-step reports is the standard deviation of the
// model's per-point log-likelihoods over sqrt(N). One pass from a model
// evaluates exactly that model; score_samples computes the same per-point
// values in double. Bound 1e-3 relative: the kernels' float32 log-densities
// of these metre-scale points are within ~1e-4 nats of the double ones on
// sse2, avx2 and avx512 alike (the same formula; only the lane count
// differs), against a per-point spread of over a nat; a wrong normalisation
// (sd instead of sd / sqrt(N)) is off by a factor of 63.
TEST(EmNoiseStop, StandardErrorIsTheScoresSpreadOverRootN) {
  const std::vector<float> pts = sogmm_test::frame_points();
  const std::size_t n = pts.size() / 4;
  sogmm::EmOptions o;
  o.max_iter = 15;
  const sogmm::Gmm model = sogmm::fit_em(view(pts), sogmm::kmeanspp_seeds(view(pts), kK, 0), o);
  sogmm::EmOptions one;
  one.max_iter = 1;
  one.tol_standard_errors = 1e-12;  // measured only when the rule reads it (EmReport::standard_error)
  sogmm::EmReport r;
  sogmm::fit_em_from(view(pts), model, one, &r);
  std::vector<double> score(n);
  sogmm::score_samples(model, pts.data(), n, 4, score.data());
  double mean = 0.0;
  for (double s : score) mean += s;
  mean /= static_cast<double>(n);
  double var = 0.0;
  for (double s : score) var += (s - mean) * (s - mean);
  const double expected = std::sqrt(var / static_cast<double>(n) / static_cast<double>(n));
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(r.standard_error, expected, 1e-3 * expected);
  EXPECT_NEAR(r.log_likelihood, mean, 1e-4);
}

// Plain EM stops at the first pass i >= 2 whose change |ll_i - ll_(i-1)| is
// below max(tol, c x se_i), se_i that pass's standard error. The trace of a
// run whose test never fires (c = 1e-12 < tol / se, tol 1e-12) gives ll_i; a
// run stopped at i passes gives se_i (with c > 0 the passes are the same
// computations whatever c and max_iter, so the comparison is exact on every
// kernel; c = 0 sums the log-likelihood in another order). c = 0.2, the
// value the README measured on real frames, stops at pass 7 here, c = 0.05
// at pass 15 (measured on avx512).
TEST(EmNoiseStop, StopsAtTheFirstPassBelowCStandardErrors) {
  const std::vector<float> pts = sogmm_test::frame_points();
  sogmm::EmOptions traced;
  traced.tol = 1e-12;
  traced.tol_standard_errors = 1e-12;
  traced.max_iter = 80;
  std::vector<double> ll;
  run(pts, traced, &ll);
  ASSERT_EQ(ll.size(), 80u);
  std::vector<double> se_cache(ll.size() + 1, -1.0);
  const auto se = [&](int i) {  // run up to the passes the rule asks about
    if (se_cache[i] < 0) {
      sogmm::EmOptions o = traced;
      o.max_iter = i;
      se_cache[i] = run(pts, o).standard_error;
    }
    return se_cache[i];
  };
  for (double c : {0.05, 0.2}) {
    SCOPED_TRACE("c " + std::to_string(c));
    const double tol = 1e-6;
    int expected = 0;
    for (int i = 2; i <= 80 && expected == 0; ++i)
      if (std::fabs(ll[i - 1] - ll[i - 2]) < std::max(tol, c * se(i))) expected = i;
    ASSERT_GE(expected, 3) << "the case must stop on the rule, not on the first pass";
    ASSERT_LT(expected, 80);
    sogmm::EmOptions o = traced;
    o.tol = tol;
    o.tol_standard_errors = c;
    std::vector<double> got;
    const sogmm::EmReport r = run(pts, o, &got);
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.iterations, expected);
    EXPECT_EQ(r.log_likelihood, ll[expected - 1]);
    EXPECT_EQ(r.standard_error, se(expected));
  }
}

// tol stays a floor (a c whose threshold is below tol changes nothing) and
// tol = 0 still runs max_iter passes; with SQUAREM the same test ends the
// run (a huge c: at the second pass, the first with a change to compare).
TEST(EmNoiseStop, TolIsAFloorAndZeroTolRunsMaxIter) {
  const std::vector<float> pts = sogmm_test::frame_points();
  sogmm::EmOptions plain;
  plain.tol = 1e-3;
  plain.tol_standard_errors = 1e-12;
  std::vector<double> a, b, off;
  const sogmm::EmReport r0 = run(pts, plain, &a);
  plain.tol_standard_errors = 1e-9;
  const sogmm::EmReport r1 = run(pts, plain, &b);
  EXPECT_EQ(r1.iterations, r0.iterations);
  EXPECT_EQ(a, b);
  // c = 0 (no standard error measured) sums the same log-likelihoods in
  // another order: the same passes, each mean within rounding.
  plain.tol_standard_errors = 0.0;
  const sogmm::EmReport r2 = run(pts, plain, &off);
  EXPECT_EQ(r2.iterations, r0.iterations);
  EXPECT_EQ(r2.standard_error, 0.0);
  ASSERT_EQ(off.size(), a.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(off[i], a[i], 1e-9) << "pass " << i;
  plain.tol = 0.0;
  plain.tol_standard_errors = 1e9;
  plain.max_iter = 7;
  EXPECT_EQ(run(pts, plain).iterations, 7);
  for (auto acc : {sogmm::EmAcceleration::None, sogmm::EmAcceleration::Squarem}) {
    sogmm::EmOptions o;
    o.tol = 1e-3;
    o.acceleration = acc;
    o.tol_standard_errors = 1e9;
    const sogmm::EmReport r = run(pts, o);
    EXPECT_TRUE(r.converged);
    EXPECT_EQ(r.iterations, 2);
  }
}

// A negative or non-finite c is refused before any work, naming the option.
TEST(EmNoiseStop, RefusesNegativeOrNonFiniteC) {
  const std::vector<float> pts = sogmm_test::frame_points();
  for (double c : {-0.1, std::nan(""), std::numeric_limits<double>::infinity()}) {
    sogmm::EmOptions o;
    o.tol_standard_errors = c;
    try {
      run(pts, o);
      ADD_FAILURE() << "c " << c << " accepted";
    } catch (const sogmm::Error& e) {
      EXPECT_EQ(e.code(), sogmm::ErrorCode::InvalidArgument);
      EXPECT_NE(std::string(e.what()).find("tol_standard_errors"), std::string::npos) << e.what();
    }
  }
}
