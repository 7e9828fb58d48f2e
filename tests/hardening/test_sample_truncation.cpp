// Sampling with a truncation (issue 13 finding 5, issue 14 item 8): each
// whitened coordinate is drawn from the standard normal truncated to (-t, t)
// by inverting its CDF, one random number per coordinate, so the cost does not
// depend on t. The former rejection loop needed 1 / P(|Z| < t) draws per
// coordinate and never returned at t = 1e-8.
//
// Independent truth: the C library's erf / erfc (not the AS 241 quantile code
// under test) and the closed-form CDF of the truncated normal,
// F_t(z) = 1/2 + erf(z / sqrt 2) / (2 erf(t / sqrt 2)) on (-t, t).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "child_process.hpp"
#include "sogmm/inference.hpp"
#include "sogmm/normal_quantile.hpp"
#include "sogmm/sogmm.h"

namespace {

constexpr double kSqrtHalf = 0.70710678118654752440;

double truncated_cdf(double z, double t) { return 0.5 + 0.5 * std::erf(z * kSqrtHalf) / std::erf(t * kSqrtHalf); }

// Kolmogorov-Smirnov distance between the values `x` and the truncated CDF.
double ks_distance(std::vector<double> x, double t) {
  std::sort(x.begin(), x.end());
  const double n = static_cast<double>(x.size());
  double d = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double f = truncated_cdf(x[i], t);
    d = std::max({d, f - static_cast<double>(i) / n, static_cast<double>(i + 1) / n - f});
  }
  return d;
}

// D sqrt(n) above 1.95 has probability 0.001 for a correct sampler (the
// Kolmogorov distribution); the seeds are fixed, so the verdict is too.
constexpr double kKsLimit = 1.95;

// Coordinate `c` of `n` rows of 4 floats.
std::vector<double> column(const std::vector<float>& rows, int c) {
  std::vector<double> v(rows.size() / 4);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = rows[4 * i + c];
  return v;
}

// One component with mean 0 and identity covariance: samples are z itself.
const float kWeight[1] = {1.0f};
const float kMean[4] = {0, 0, 0, 0};
const float kIdentity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

sogmm::Gmm standard_normal() {
  sogmm::Gmm g;
  g.resize(1);
  g.weights[0] = kWeight[0];
  std::copy(kMean, kMean + 4, g.means.begin());
  std::copy(kIdentity, kIdentity + 16, g.covariances.begin());
  return g;
}

TEST(NormalQuantile, CentralBranchInvertsTheCdf) {
  // Phi(z) - 1/2 = erf(z / sqrt 2) / 2, relative accuracy even for tiny offsets.
  for (double c : {1e-300, 1e-12, 1e-6, 0.01, 0.1, 0.2, 0.3, 0.4, 0.425}) {
    for (double sign : {1.0, -1.0}) {
      const double z = sogmm::normal_quantile_central(sign * c);
      EXPECT_NEAR(0.5 * std::erf(z * kSqrtHalf) / (sign * c), 1.0, 1e-14) << "c = " << sign * c << ", z = " << z;
    }
  }
}

TEST(NormalQuantile, TailBranchInvertsTheCdf) {
  // P(Z > z) = erfc(z / sqrt 2) / 2; both rational branches (r <= 5 and r > 5).
  for (double t : {0.075, 0.05, 1e-3, 1e-6, 1e-10, 1e-11, 1e-16, 1e-30, 1e-100, 1e-300}) {
    const double z = sogmm::normal_quantile_upper_tail(t);
    // A relative error e in z is one of about z^2 e in the tail probability.
    EXPECT_NEAR(0.5 * std::erfc(z * kSqrtHalf) / t, 1.0, 1e-15 * (1.0 + z * z)) << "t = " << t << ", z = " << z;
  }
}

TEST(SampleTruncation, CoordinatesFollowTheTruncatedNormal) {
  const sogmm::Gmm g = standard_normal();
  const std::size_t n = 200000;
  for (double t : {2.5, 1.0, 0.05}) {
    std::vector<float> x(4 * n);
    sogmm::sample(g, n, 11, 4, x.data(), t);
    for (int c = 0; c < 4; ++c) {
      const std::vector<double> v = column(x, c);
      EXPECT_LT(ks_distance(v, t) * std::sqrt(static_cast<double>(n)), kKsLimit) << "t = " << t << ", coordinate " << c;
      for (double z : v) ASSERT_LE(std::fabs(z), static_cast<float>(t)) << "a coordinate beyond t = " << t;
    }
  }
}

// Through the C API, in a child process (the rejection sampler never returned
// here): t = 1e-8 gives samples inside (-t, t) that follow F_t, drawn from the
// same random numbers as t = 2.5 with the same seed, coordinate for coordinate
// (F_1e-8(z') = F_2.5(z)). So each coordinate takes one draw whatever t is.
std::string tiny_truncation_problem() {
  const std::size_t n = 100000;
  const double tiny = 1e-8, usual = 2.5;
  sogmm_model* m = nullptr;
  sogmm_options* o = nullptr;
  std::vector<float> a(4 * n), b(4 * n);
  const bool ok = sogmm_model_from_arrays_f32(&m, 1, kWeight, kMean, kIdentity, 0) == SOGMM_OK &&
                  sogmm_options_create(&o) == SOGMM_OK &&
                  sogmm_options_set_f64(o, SOGMM_OPT_SAMPLE_TRUNCATION, tiny) == SOGMM_OK &&
                  sogmm_model_sample_f32(m, n, 7, 4, o, a.data()) == SOGMM_OK &&
                  sogmm_options_set_f64(o, SOGMM_OPT_SAMPLE_TRUNCATION, usual) == SOGMM_OK &&
                  sogmm_model_sample_f32(m, n, 7, 4, o, b.data()) == SOGMM_OK;
  const std::string error = ok ? "" : std::string("a C API call failed: ") + sogmm_last_error();
  sogmm_options_free(o);
  sogmm_model_free(m);
  if (!ok) return error;
  std::ostringstream problem;
  for (int c = 0; c < 4; ++c) {
    const std::vector<double> v = column(a, c);
    const double d = ks_distance(v, tiny) * std::sqrt(static_cast<double>(n));
    if (!(d < kKsLimit)) problem << "coordinate " << c << ": KS D sqrt(n) = " << d << " at t = 1e-8. ";
  }
  double worst_gap = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!(std::fabs(a[i]) <= static_cast<float>(tiny))) {
      problem << "value " << a[i] << " beyond t = 1e-8. ";
      break;
    }
    // float rounding of z moves F by at most about 1e-7 at either t.
    worst_gap = std::max(worst_gap, std::fabs(truncated_cdf(a[i], tiny) - truncated_cdf(b[i], usual)));
  }
  if (!(worst_gap < 1e-6)) problem << "t = 1e-8 and t = 2.5 are not driven by the same draws: F differs by " << worst_gap;
  return problem.str();
}

TEST(SampleTruncation, TinyTruncationTakesOneDrawPerCoordinate) {
  sogmm::test::expect_child_succeeds(tiny_truncation_problem, 120);
}

}  // namespace
